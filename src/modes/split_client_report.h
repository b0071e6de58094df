#pragma once
// What only the client of the split (`--mode edge`) has to report: its own bounded map, what full
// resyncs did to its keyframes and the points it triangulated itself. The run command reads it
// through SlamSystem::splitClientReport(), whatever the mode.
#include <cstddef>
#include <cstdint>

#include "client/tracker.h"

namespace edgeslam {

// The client's own map (bounded or not): what it holds now and the most it held.
struct ClientMapSize {
  std::size_t keyframes = 0;  // held: with features and points (not evicted)
  std::size_t points = 0;
  std::size_t max_keyframes = 0;
  std::size_t max_points = 0;
  std::size_t keyframes_evicted = 0;  // evictions applied over the run
  std::size_t keyframes_entered = 0;  // keyframes sent back into the window
};

// What full resyncs (a reconnection after the edge lost its session) did to the client's
// keyframes: each one the client made is on the edge, re-sent, or lost for a reason counted here.
struct ResyncCounters {
  std::uint64_t full_resyncs = 0;      // slices with full_resync applied
  std::uint64_t keyframes_resent = 0;  // the edge lacked them: uploaded again
  // The edge lacked them and the client no longer had their features (evicted from its bounded
  // map before the edge stored them): lost.
  std::uint64_t keyframes_lost_evicted = 0;
  // This client's keyframes the edge erased (culled as redundant, on a revisit say): neither in
  // the edge map nor lost.
  std::uint64_t keyframes_culled_by_edge = 0;
};

struct SplitClientReport {
  ClientMapSize client_map;
  ResyncCounters resync;
  KeyFrameTriangulationStats triangulation;  // monocular: points the client made itself
};

}  // namespace edgeslam
