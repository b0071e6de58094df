#pragma once
// `edgeslam server --metrics FILE`: the server's own metrics.json, rewritten at every status line
// and at stop: open sessions and what closed sessions received and left undelivered.
#include <filesystem>
#include <nlohmann/json.hpp>

#include "store/map_store_writer.h"
#include "wire/edge_server.h"

namespace edgeslam {

// `store`: the map store's writes (nullptr: the server keeps no store).
nlohmann::json serverMetricsJson(const EdgeServer& server, double uptime_s,
                                 const MapStoreWriteStats* store = nullptr);
// Written to a temporary file first and renamed, so a reader never sees half a file.
void writeServerMetrics(const std::filesystem::path& file, const nlohmann::json& metrics);

}  // namespace edgeslam
