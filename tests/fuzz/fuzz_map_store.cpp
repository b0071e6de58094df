// Map store files (`--maps PATH`, `edgeslam map ...`): a damaged maps.sqlite opened read-only,
// every map listed, summarised, loaded and rebuilt into a Map as a server resuming it would, with
// the stored bags of words attached (checked against a small vocabulary: words and nodes beyond
// it, features beyond the keyframe's).
#include <exception>
#include <filesystem>

#include "fuzz_file.h"
#include "map/map.h"
#include "place/vocabulary.h"
#include "store/map_store.h"
#include "store/stored_map_loader.h"

namespace {

// k = 2, L = 2: 7 nodes, 4 words.
const edgeslam::Vocabulary& smallVocabulary() {
  static const edgeslam::Vocabulary vocabulary = [] {
    edgeslam::VocabularyTree tree;
    tree.branching = 2;
    tree.levels = 2;
    tree.parents = {edgeslam::kNoParent, 0, 0, 1, 1, 2, 2};
    tree.centres.resize(tree.parents.size());
    for (std::size_t i = 0; i < tree.centres.size(); ++i)
      tree.centres[i].words[0] = 0x9E3779B97F4A7C15ULL * i;
    tree.weights = {0, 0, 0, 1, 1, 1, 1};
    tree.training_images = 1;
    tree.training_descriptors = 4;
    return edgeslam::Vocabulary(std::move(tree));
  }();
  return vocabulary;
}

}  // namespace

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
        // Whatever vocabulary the damaged rows name is taken as this one.
        for (const edgeslam::KeyFramePlaceRecord& place : session.places) {
          (void)edgeslam::attachStoredPlaces(session, map, smallVocabulary(), place.vocabulary,
                                             place.direct_index_depth);
          break;
        }
      }
    }
  } catch (const std::exception&) {
  }
  return 0;
}
