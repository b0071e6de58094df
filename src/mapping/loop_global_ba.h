#pragma once
// Global bundle adjustment after a loop correction: every keyframe and point of the part of the map
// the loop is in (keyframes joined to it through points they observe together; a map of several
// parts not yet joined, such as sessions never merged or a stored map's unconnected pieces, adjusts
// only that part), the map's origin fixed, or the part's oldest keyframe where the origin is
// elsewhere.
// Built under the map's update mutex, solved without it (tracking and mapping go on), and applied
// through the Map: keyframes and points made during the solve follow the corrected keyframes
// (loop_map_correction.h). A cancelled run changes nothing.
#include <atomic>
#include <cstddef>
#include <functional>
#include <vector>

#include "geometry/camera.h"
#include "map/map.h"

namespace edgeslam {

struct LoopGlobalBundleAdjustmentResult {
  bool applied = false;
  bool cancelled = false;
  bool too_large = false;  // the part had more than max_keyframes: not adjusted
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

// `loop_keyframe`: a keyframe of the part to adjust (nullptr: the whole map). A part of more than
// `max_keyframes` keyframes (0: no bound) is left as it is (too_large): one iteration of a
// problem that size outlasts the next loop, which then waits for it to notice it is cancelled.
LoopGlobalBundleAdjustmentResult runLoopGlobalBundleAdjustment(
    Map& map, const PinholeCamera& camera, const std::atomic<bool>* cancel, int iterations,
    const GlobalBundleAdjustmentHooks& hooks = {}, const KeyFrame* loop_keyframe = nullptr,
    std::size_t max_keyframes = 0) EXCLUDES(map.updateMutex());

// The keyframes joined to `seed` through map points they both observe (seed included, if good).
std::vector<KeyFrame*> connectedKeyFrames(const Map& map, const KeyFrame* seed)
    REQUIRES(map.updateMutex());

}  // namespace edgeslam
