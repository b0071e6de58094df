#include "server_metrics.h"

#include <fmt/format.h>

#include <fstream>
#include <stdexcept>

#include "util/resident_memory.h"

namespace edgeslam {

namespace {

nlohmann::json summaryJson(const PercentileSummary& s) {
  return {{"count", s.count}, {"median", s.median}, {"p90", s.p90},   {"p95", s.p95},
          {"p99", s.p99},     {"max", s.max},       {"mean", s.mean}, {"total", s.mean * s.count}};
}

nlohmann::json sessionJson(const SessionStats& s) {
  nlohmann::json stages = nlohmann::json::object();
  for (const auto& [stage, summary] : s.costs.stages_ms) stages[stage] = summaryJson(summary);
  return {{"session_id", fmt::format("{:#x}", s.session_id)},
          {"client_name", s.client_name},
          {"keyframes", s.keyframes},
          {"duplicate_uploads", s.duplicate_uploads},
          {"missing_uploads", s.missing_uploads},
          {"frames", s.frames},
          {"uplink_bytes", s.uplink_bytes},
          {"downlink_bytes", s.downlink_bytes},
          {"slices_pushed", s.slices_pushed},
          {"slices_sent", s.slices_sent},
          {"slices_acknowledged", s.slices_acknowledged},
          {"slices_dropped", s.slices_dropped},
          {"streaming", s.streaming},
          {"map_keyframes", s.costs.map_keyframes},
          {"map_points", s.costs.map_points},
          {"backend_ms", stages}};
}

}  // namespace

nlohmann::json serverMetricsJson(const EdgeServer& server, double uptime_s,
                                 const MapStoreWriteStats* store) {
  nlohmann::json open = nlohmann::json::array();
  for (const SessionStats& s : server.sessions(true)) open.push_back(sessionJson(s));
  const ClosedSessionTotals c = server.closedSessions();
  nlohmann::json metrics = {{"uptime_s", uptime_s},
                            {"rss_bytes", residentBytes()},
                            {"sessions_open", open.size()},
                            {"sessions", open},
                            {"closed_sessions",
                             {{"sessions", c.sessions},
                              {"by_client", c.closed_by_client},
                              {"idle", c.closed_idle},
                              {"reclaimed", c.closed_reclaimed},
                              {"at_shutdown", c.closed_at_shutdown},
                              {"failed", c.closed_failed},
                              {"keyframes", c.keyframes},
                              {"duplicate_uploads", c.duplicate_uploads},
                              {"missing_uploads", c.missing_uploads},
                              {"slices_pushed", c.slices_pushed},
                              {"slices_dropped", c.slices_dropped},
                              {"slices_unacknowledged", c.slices_unacknowledged}}}};
  nlohmann::json recent = nlohmann::json::array();
  for (const SessionStats& s : c.recent) recent.push_back(sessionJson(s));
  metrics["closed_sessions"]["recent"] = std::move(recent);
  if (store != nullptr) {
    const MapStoreWriteStats::Totals t = store->totals();
    metrics["store"] = {{"batches", t.batches},
                        {"keyframes_written", t.keyframes_written},
                        {"points_written", t.points_written},
                        {"points_moved", t.points_moved},
                        {"failures", t.failures},
                        {"write_ms", summaryJson(t.write_ms)},
                        {"copy_ms", summaryJson(t.copy_ms)}};
  }
  return metrics;
}

void writeServerMetrics(const std::filesystem::path& file, const nlohmann::json& metrics) {
  const std::filesystem::path temporary = file.string() + ".tmp";
  {
    std::ofstream out(temporary);
    out << metrics.dump(2) << '\n';
    if (!out) throw std::runtime_error(fmt::format("cannot write {}", temporary.string()));
  }
  std::filesystem::rename(temporary, file);
}

}  // namespace edgeslam
