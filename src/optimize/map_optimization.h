#pragma once
// Adapters between the map types and the Ceres problems: pose-only optimisation of a Frame, local
// bundle adjustment around a keyframe, and global bundle adjustment. Callers do not hold the map's
// update mutex: these take it to read the problem and to write the result back, and solve unlocked.
#include <atomic>
#include <cstddef>
#include <string>

#include "geometry/camera.h"
#include "map/frame.h"
#include "map/map.h"
#include "optimize/intrinsics_refinement.h"
#include "optimize/local_bundle_adjustment.h"
#include "optimize/pose_optimizer.h"

namespace edgeslam {

// Refines frame.T_cw against its matched points (held fixed) and marks frame.outliers. Returns the
// number of inliers. The caller holds whatever lock protects the points.
int optimizeFramePose(Frame& frame, const PoseOptimizerOptions& options = {});

struct LocalBundleAdjustmentStats {
  std::size_t keyframes = 0;        // optimised
  std::size_t fixed_keyframes = 0;  // seen by the window's points, held fixed
  std::size_t points = 0;
  std::size_t observations = 0;
  std::size_t outliers_removed = 0;
  double rms_before = 0.0;
  double rms_after = 0.0;
  bool cancelled = false;
  double solve_ms = 0.0;
};

// Optimises `keyframe` and its covisible keyframes with every point they see; the other keyframes
// that see those points stay fixed. Locks `map` while reading and writing, not while solving.
LocalBundleAdjustmentStats localBundleAdjustment(Map& map, KeyFrame* keyframe,
                                                 const PinholeCamera& camera,
                                                 const std::atomic<bool>* cancel = nullptr,
                                                 BundleAdjustmentOptions options = {})
    EXCLUDES(map.updateMutex());

// Every keyframe and point; the origin keyframe fixed. Same locking as above.
LocalBundleAdjustmentStats globalBundleAdjustment(Map& map, const PinholeCamera& camera,
                                                  const std::atomic<bool>* cancel = nullptr,
                                                  int iterations = 20) EXCLUDES(map.updateMutex());

struct MapIntrinsicsRefinement {
  IntrinsicsRefinementResult result;
  std::size_t keyframes = 0;
  std::size_t points = 0;
  double solve_ms = 0.0;
};

// Self-calibrating global bundle adjustment (intrinsics_refinement.h) over every keyframe and
// point, the origin keyframe fixed. When the refinement is adopted the map takes its keyframe
// poses and point positions; the keyframes' keypoints stay undistorted with `camera`, so this is
// for a finished map (the end of a run), whose refined camera the caller reports. Same locking as
// above.
// One line for logs and summaries: the refined values and the RMS, or why they were kept.
std::string describe(const MapIntrinsicsRefinement& refinement);

MapIntrinsicsRefinement refineMapIntrinsics(Map& map, const PinholeCamera& camera,
                                            const IntrinsicsRefinementOptions& options = {})
    EXCLUDES(map.updateMutex());

}  // namespace edgeslam
