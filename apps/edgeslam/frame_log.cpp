#include "frame_log.h"

#include <fmt/format.h>

#include <fstream>
#include <stdexcept>

namespace edgeslam::cli {

void writeFrameLog(const std::filesystem::path& path, const std::vector<FrameLogEntry>& entries) {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
  out << "frame,timestamp,state,keyframe,relocalized,tracked_points,load_ms,client_ms,e2e_ms,"
         "features_ms,tracking_ms,keyframe_ms,uplink_bytes,downlink_bytes,adaptation_row,"
         "features_culled,features,levels\n";
  for (const FrameLogEntry& e : entries) {
    out << fmt::format(
        "{},{:.6f},{},{:d},{:d},{},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{:.3f},{},{},{},{},{},{}\n",
        e.index, e.timestamp, toString(e.state), e.keyframe, e.relocalized, e.tracked_points,
        e.load_ms, e.client_ms, e.e2e_ms, e.features_ms, e.tracking_ms, e.keyframe_ms,
        e.uplink_bytes, e.downlink_bytes, e.adaptation_row, e.features_culled, e.features,
        e.levels);
  }
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", path.string()));
}

}  // namespace edgeslam::cli
