#pragma once
// `--maps PATH|none` (server, run) and `--map NAME` (run, client): where edge maps persist.
#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "store/map_store.h"
#include "store/map_store_writer.h"

namespace edgeslam::cli {

struct MapStoreChoice {
  std::shared_ptr<MapStore> store;  // nullptr: maps are not kept
  std::shared_ptr<MapStoreWriteStats> stats;
};

// "none": no store. "": the per-user default, and when that cannot be used (read-only home,
// another process writing to it) a warning and no store: a run must not fail for it. A PATH given
// must open (StoreError otherwise).
MapStoreChoice openStoreForWriting(const std::string& maps);

// The store folder the `map` commands read: PATH, or the default ("" given).
std::filesystem::path storeDirectory(const std::string& maps);

void addMapsOption(CLI::App* command, std::string& maps);

// metrics.json's "store" block for the map `name`: what the writers wrote and the map's size.
nlohmann::json storeMetrics(const MapStoreChoice& choice, const std::string& name);

// The run's warning when writes to the store failed ("" when none did): how many, and what the
// stored map holds of the run's `keyframes`.
std::string storeWarning(const nlohmann::json& store_metrics, std::size_t keyframes);

}  // namespace edgeslam::cli
