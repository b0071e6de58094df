#pragma once
// What a finished run says when it ended worse than it could have: the figures that point at a
// map the machine's speed, not the data, made worse (issue 24, item 6). Each warning is one line
// for the summary and an entry of metrics.json's `warnings`.
#include <cstddef>
#include <string>
#include <vector>

namespace edgeslam {

struct RunHealth {
  std::size_t frames = 0;  // frames of the run, dropped ones included
  std::size_t tracked = 0;
  std::size_t lost = 0;
  std::size_t frames_dropped_late = 0;    // --realtime: the client fell behind the camera
  std::size_t backend_busy_refusals = 0;  // frames at which the back end could take no keyframe
  double backend_wait_ms = 0.0;           // --fast: tracking's total wait for the back end
  double wall_ms = 0.0;
  bool monocular = false;
  double keyframe_depth_ratio = 0.0;    // late / early keyframes' median depth (0 = unknown)
  std::size_t frames_out_of_order = 0;  // skipped: timestamp repeated or going back
  std::size_t frames_without_map = 0;   // processed before the first map (or after a reset)
  bool map_built = true;
  std::string refusals = {};  // initialisation refusals by cause, most frequent first ("" = none)
  // Maps started after tracking was lost for good that no loop merged back (each keeps a frame of
  // its own: one alignment does not fit the whole trajectory).
  std::size_t maps_unmerged = 0;
};

struct RunWarningThresholds {
  double max_lost_fraction = 0.10;
  // Of the tracked frames: more and the map was built with keyframes the back end could not take.
  double max_busy_fraction = 0.10;
  // Of the wall time: more and the run is bound by the back end (a hint, not an error).
  double max_wait_fraction = 0.50;
  // Monocular: the scene's depth changing by more than this factor suggests scale drift (KITTI 07
  // edge runs that ended at 25-34 cm moved it by 1.7-2.3x: only gross drift is told).
  double max_depth_ratio = 3.0;
};

std::vector<std::string> runWarnings(const RunHealth& health,
                                     const RunWarningThresholds& thresholds = {});

}  // namespace edgeslam
