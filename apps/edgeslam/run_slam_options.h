#pragma once
// What a run's flags make of the SLAM options (ORB, keyframe rules, vocabulary, back end,
// semantics, intrinsics refinement), after refusing the flags that apply to one mode only.
#include "geometry/camera.h"
#include "map/sensor.h"
#include "modes/slam_system.h"
#include "run_options.h"

namespace edgeslam::cli {

// Throws CLI::ValidationError for flags that do not go together (--deterministic, --localize-only
// and --route outside the modes they serve). Sets OpenCV's thread count to 1 where a run must not
// share cores with OpenCV's pool (--deterministic, semantic culling in this process).
SlamOptions slamOptionsForRun(const RunOptions& options, const PinholeCamera& camera,
                              Sensor sensor);

}  // namespace edgeslam::cli
