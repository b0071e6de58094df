#pragma once
// Per-frame record of a run, written next to metrics.json as frames.csv: where the time went
// frame by frame (a stall and the backlog it leaves show up here, not in the percentiles).
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <vector>

#include "client/tracking_types.h"

namespace edgeslam::cli {

struct FrameLogEntry {
  std::size_t index = 0;
  double timestamp = 0.0;
  TrackingState state = TrackingState::kNotInitialized;
  bool keyframe = false;
  bool relocalized = false;
  int tracked_points = 0;
  double load_ms = 0.0;
  double client_ms = 0.0;
  double e2e_ms = 0.0;
  double features_ms = 0.0;  // client_ms split by stage (zero in offload mode)
  double tracking_ms = 0.0;
  double keyframe_ms = 0.0;
  std::uint64_t uplink_bytes = 0;  // over the link so far (zero in local mode)
  std::uint64_t downlink_bytes = 0;
  int adaptation_row = -1;  // Table I row in use (0-based); -1 without self-adaptation
  int features_culled = 0;  // by semantic culling in this frame
  int features = 0;         // the extraction this frame had (zero where the client extracts none)
  int levels = 0;
};

// Columns: frame,timestamp,state,keyframe,relocalized,tracked_points,load_ms,client_ms,e2e_ms,
// features_ms,tracking_ms,keyframe_ms,uplink_bytes,downlink_bytes,adaptation_row,features_culled,
// features,levels.
// Throws std::runtime_error naming the file when it cannot be written.
void writeFrameLog(const std::filesystem::path& path, const std::vector<FrameLogEntry>& entries);

}  // namespace edgeslam::cli
