#include "server_metrics.h"

#include <fmt/format.h>

#include <fstream>
#include <stdexcept>

#include "util/resident_memory.h"

namespace edgeslam {

nlohmann::json serverMetricsJson(const EdgeServer& server, double uptime_s) {
  nlohmann::json open = nlohmann::json::array();
  for (const SessionStats& s : server.sessions()) {
    open.push_back({{"session_id", fmt::format("{:#x}", s.session_id)},
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
                    {"streaming", s.streaming}});
  }
  const ClosedSessionTotals c = server.closedSessions();
  return {{"uptime_s", uptime_s},
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
