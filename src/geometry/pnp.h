#pragma once
// Camera pose from 2D-3D correspondences: RANSAC over minimal P3P solutions (OpenCV's AP3P),
// then Levenberg-Marquardt refinement of the reprojection error on the inliers. Used for
// relocalisation.
#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "geometry/se3.h"

namespace edgeslam {

struct PnpOptions {
  int max_iterations = 200;
  double reprojection_threshold_px = 2.45;  // sqrt(chi2 5.991) at sigma = 1 px
  double confidence = 0.99;
  int min_correspondences = 6;
  int min_inliers = 10;
  bool refine = true;
};

struct PnpResult {
  bool success = false;
  std::string reason;  // why it failed (empty on success)
  SE3d camera_from_world;
  std::vector<char> inliers;  // one flag per correspondence
  int num_inliers = 0;
  double rmse_px = 0.0;  // reprojection RMSE over the inliers
};

// pixels: undistorted pixel observations; points_world: the matching 3D points; K: calibration.
// Degenerate input (too few points, coincident or collinear world points, coincident pixels) is
// reported as a failure with a reason. Throws std::invalid_argument on mismatched sizes,
// non-finite values or a bad K / options.
PnpResult solvePnpRansac(std::span<const Eigen::Vector2d> pixels,
                         std::span<const Eigen::Vector3d> points_world, const Eigen::Matrix3d& K,
                         const PnpOptions& options = {});

}  // namespace edgeslam
