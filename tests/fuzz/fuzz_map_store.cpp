// Map store files (`--maps PATH`, `edgeslam map ...`): a damaged maps.sqlite opened read-only,
// every map listed, summarised, loaded and rebuilt into a Map as a server resuming it would.
#include <exception>
#include <filesystem>

#include "fuzz_file.h"
#include "map/map.h"
#include "store/map_store.h"
#include "store/stored_map_loader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path dir = edgeslam::fuzz::scratchDir() / "store";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const auto written = edgeslam::fuzz::writeInput("store.sqlite", data, size);
  std::filesystem::rename(written, dir / "maps.sqlite");
  try {
    auto store = edgeslam::openMapStore(dir, edgeslam::MapStoreAccess::kRead);
    for (const edgeslam::MapSummary& summary : store->listMaps()) {
      (void)store->mapInfo(summary.name);
      const auto stored = store->loadMap(summary.name);
      if (!stored) continue;
      for (const edgeslam::StoredSession& session : stored->sessions) {
        edgeslam::Map map;
        edgeslam::loadStoredSession(session, map);
      }
    }
  } catch (const std::exception&) {
  }
  return 0;
}
