#pragma once
// The run's frame loop: plays the dataset into a SlamSystem (as a live camera with --realtime, back
// to back otherwise) and gathers what the report needs; the run's companions (viewer, semantic
// scoring, passes of --repeat, a route to follow) see every frame.
#include <cstddef>
#include <functional>
#include <optional>
#include <utility>
#include <vector>

#include "adapt/compute_budget.h"
#include "frame_log.h"
#include "io/dataset.h"
#include "io/frame_order_guard.h"
#include "io/trajectory.h"
#include "modes/slam_system.h"
#include "repeat_passes.h"
#include "util/timing_stats.h"
#include "viz/view_snapshot.h"

namespace edgeslam::cli {

class RunViewer;
class SemanticEvaluation;
class RouteFollowing;

struct FramePlan {
  std::size_t frame_count = 0;      // frames to play (all passes)
  std::size_t frames_per_pass = 0;  // of the selected range, before --repeat
  bool realtime = false;
  // The client's per-frame work fitted to its CPU (with realtime; adapt/compute_budget.h).
  std::optional<ComputeBudgetOptions> compute_budget;
};

// Optional parts that watch the frames go by; each may be absent.
struct RunCompanions {
  RunViewer* viewer = nullptr;
  viz::RunStatus view_status;  // the viewer's status line: what does not change per frame
  SemanticEvaluation* semantic_eval = nullptr;
  PassLog* pass_log = nullptr;
  RouteFollowing* route = nullptr;
  std::function<std::optional<EdgeMapSize>()> edge_map_size;
};

struct PlayedFrames {
  // e2e: from the frame's arrival to its pose. With --realtime a frame arrives at its due time on
  // the camera clock (so reading it and any backlog count); otherwise when it has been read.
  SampleStats client_ms, load_ms, e2e_ms;
  std::vector<FrameLogEntry> frame_log;
  Trajectory ground_truth;  // the dataset's poses at the frames played
  std::size_t tracked = 0;  // in the map the run ends with
  std::size_t lost = 0;
  std::size_t tracked_in_discarded_maps = 0;
  FrameOrderGuard frame_order;
  // A live camera's (--realtime): frames it skipped because a newer one was due, and its reads.
  bool live = false;
  std::size_t frames_skipped_late = 0;
  std::size_t frames_read = 0;
  std::size_t frames_read_unused = 0;
  // What the compute budget did, when there was one; `configured` is the extraction it started
  // from (features, levels).
  std::optional<ComputeBudget> compute_budget;
  std::pair<int, int> configured_extraction{0, 0};
};

// Plays the frames; `wall` is the run's clock (started before the first frame).
PlayedFrames playFrames(DatasetReader& reader, const FramePlan& plan, SlamSystem& slam,
                        RunCompanions& companions, const Stopwatch& wall);

}  // namespace edgeslam::cli
