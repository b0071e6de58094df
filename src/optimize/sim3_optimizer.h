#pragma once
// Refinement of the similarity between two keyframes for loop closing: S_12 (points of keyframe 2's
// camera frame into keyframe 1's) minimising the reprojection errors of the matched points in both
// images, with a robust kernel and an outlier pass. Starts from the RANSAC estimate of
// geometry/sim3_solver.h, on the same matches.
#include <span>
#include <vector>

#include "geometry/sim3.h"
#include "geometry/sim3_solver.h"
#include "optimize/camera_projection.h"

namespace edgeslam {

struct Sim3RefinementOptions {
  int first_pass_iterations = 5;
  int second_pass_iterations = 10;
  double chi2_threshold = 10.0;  // per image, on error^2 / sigma^2
  bool fix_scale = false;        // stereo / RGB-D: keep the initial scale
  // Two monocular maps: where the camera centres are closer than this fraction of the points'
  // median range, reprojection does not see the scale (geometry/sim3_scale.h). The scale is then
  // taken from the points' ranges and held while rotation and translation are refined. 0: never.
  double scale_from_ranges_below_baseline = 0.0;
  // Below this many inliers after the outlier pass the refinement is abandoned (success = false).
  int min_inliers = 10;
};

struct Sim3RefinementResult {
  bool success = false;
  Sim3d S_12;                  // cam1_from_cam2: point1 ~= S_12 * point2
  std::vector<bool> outliers;  // one per match
  int inliers = 0;
  int iterations = 0;
  bool scale_from_ranges = false;  // the scale was held at the points' ranges (see the options)
};

// Throws std::invalid_argument for bad cameras, non-finite matches or non-positive sigmas.
Sim3RefinementResult refineSim3(const Sim3d& initial_S_12, std::span<const Sim3Match> matches,
                                const CameraProjection& camera1, const CameraProjection& camera2,
                                const Sim3RefinementOptions& options = {});

}  // namespace edgeslam
