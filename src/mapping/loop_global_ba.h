#pragma once
// Global bundle adjustment after a loop correction: every keyframe and point, the origin fixed.
// Built under the map's update mutex, solved without it (tracking and mapping go on), and applied
// through the Map: keyframes and points made during the solve follow the corrected keyframes
// (loop_map_correction.h). A cancelled run changes nothing.
#include <atomic>
#include <cstddef>
#include <functional>

#include "geometry/camera.h"
#include "map/map.h"

namespace edgeslam {

struct LoopGlobalBundleAdjustmentResult {
  bool applied = false;
  bool cancelled = false;
  std::size_t keyframes = 0;
  std::size_t points = 0;
  std::size_t observations = 0;
  std::size_t outliers_removed = 0;
  std::size_t keyframes_propagated = 0;  // made during the solve
  int iterations = 0;
  double rms_before = 0.0;
  double rms_after = 0.0;
  double solve_ms = 0.0;
};

// Called around the write-back (not when cancelled), e.g. to hold local mapping so that a local
// bundle adjustment solved from the old poses cannot land on top of the new ones.
struct GlobalBundleAdjustmentHooks {
  std::function<void()> before_apply;
  std::function<void()> after_apply;
};

LoopGlobalBundleAdjustmentResult runLoopGlobalBundleAdjustment(
    Map& map, const PinholeCamera& camera, const std::atomic<bool>* cancel, int iterations,
    const GlobalBundleAdjustmentHooks& hooks = {}) EXCLUDES(map.updateMutex());

}  // namespace edgeslam
