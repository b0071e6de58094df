#include "map_store_option.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <stdexcept>

#include "store/store_error.h"
#include "store/store_location.h"

namespace edgeslam::cli {

MapStoreChoice openStoreForWriting(const std::string& maps) {
  MapStoreChoice choice;
  if (maps == "none") return choice;
  if (!maps.empty()) {
    choice.store = openMapStore(maps, MapStoreAccess::kServe);
  } else {
    const auto directory = defaultMapStoreDirectory();
    if (!directory) {
      spdlog::warn("maps are not kept: neither XDG_DATA_HOME nor HOME is set (--maps PATH)");
      return choice;
    }
    try {
      choice.store = openMapStore(*directory, MapStoreAccess::kServe);
    } catch (const StoreError& e) {
      spdlog::warn("maps are not kept: {} (--maps PATH to choose a store, --maps none to silence)",
                   e.what());
      return choice;
    }
  }
  choice.stats = std::make_shared<MapStoreWriteStats>();
  spdlog::info("map store {}", choice.store->location());
  return choice;
}

std::filesystem::path storeDirectory(const std::string& maps) {
  if (!maps.empty()) return maps;
  const auto directory = defaultMapStoreDirectory();
  if (!directory) throw std::invalid_argument("no default map store (HOME unset): give --maps");
  return *directory;
}

void addMapsOption(CLI::App* command, std::string& maps) {
  command->add_option("--maps", maps,
                      "Map store folder (default $XDG_DATA_HOME/edgeslam or "
                      "~/.local/share/edgeslam; none = keep no maps)");
}

nlohmann::json storeMetrics(const MapStoreChoice& choice, const std::string& name) {
  if (!choice.store || !choice.stats) return nullptr;
  choice.stats->flushAll();
  const MapStoreWriteStats::Totals t = choice.stats->totals();
  const auto toJson = [](const PercentileSummary& s) {
    return nlohmann::json{{"median", s.median}, {"p90", s.p90}, {"p95", s.p95},
                          {"p99", s.p99},       {"max", s.max}, {"mean", s.mean}};
  };
  nlohmann::json out = {{"location", choice.store->location()},
                        {"map", name},
                        {"batches", t.batches},
                        {"keyframes_written", t.keyframes_written},
                        {"points_written", t.points_written},
                        {"points_moved", t.points_moved},
                        {"failures", t.failures},
                        {"write_ms", toJson(t.write_ms)},
                        {"copy_ms", toJson(t.copy_ms)}};
  if (const auto info = choice.store->mapInfo(name)) {
    out["keyframes"] = info->keyframes;
    out["points"] = info->points;
    out["bytes"] = info->bytes;
    out["bytes_per_keyframe"] = info->keyframes > 0 ? info->bytes / info->keyframes : 0;
  }
  return out;
}

std::string storeWarning(const nlohmann::json& store_metrics, std::size_t keyframes) {
  if (!store_metrics.is_object() || store_metrics.value("failures", 0) == 0) return {};
  return fmt::format(
      "map store: {} write batch(es) failed (disk full or unwritable? see the errors above); the "
      "stored map '{}' holds {} of this run's {} keyframes",
      store_metrics.value("failures", 0), store_metrics.value("map", std::string()),
      store_metrics.value("keyframes", 0), keyframes);
}

}  // namespace edgeslam::cli
