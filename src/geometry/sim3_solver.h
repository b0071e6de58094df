#pragma once
// Similarity between two keyframes from 3D-3D matches, for loop closing: closed-form absolute
// orientation with scale (Umeyama 1991) on minimal sets of three matches inside RANSAC. A match is
// an inlier when the transformed point reprojects onto its observation in both keyframes.
#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "geometry/chi_square.h"
#include "geometry/sim3.h"

namespace edgeslam {

struct Sim3Match {
  Eigen::Vector3d point1;  // the map point in keyframe 1's camera frame
  Eigen::Vector3d point2;  // its match in keyframe 2's camera frame
  Eigen::Vector2d pixel1;  // observation in keyframe 1 (undistorted)
  Eigen::Vector2d pixel2;  // observation in keyframe 2 (undistorted)
  double sigma1_px = 1.0;  // observation noise (e.g. from the pyramid level)
  double sigma2_px = 1.0;
};

struct Sim3SolverOptions {
  int max_iterations = 300;
  double confidence = 0.99;
  double chi2_threshold = chi2::k2Dof99;  // per image, on error^2 / sigma^2
  bool fix_scale = false;                 // SE(3) only (stereo / RGB-D): scale stays 1
  int min_inliers = 20;
  uint64_t seed = 0x51a3;
};

struct Sim3Result {
  bool success = false;
  std::string reason;    // why it failed (empty on success)
  Sim3d cam1_from_cam2;  // point1 ~= cam1_from_cam2 * point2
  std::vector<char> inliers;
  int num_inliers = 0;
  int iterations = 0;
};

// Least-squares X1 = s R X2 + t (s = 1 when fix_scale). nullopt for fewer than three pairs or
// degenerate (collinear / coincident) points. Throws std::invalid_argument on mismatched sizes.
std::optional<Sim3d> alignUmeyama(std::span<const Eigen::Vector3d> points1,
                                  std::span<const Eigen::Vector3d> points2, bool fix_scale);

// Throws std::invalid_argument on non-finite matches, non-positive sigmas, or bad K / options.
Sim3Result solveSim3Ransac(std::span<const Sim3Match> matches, const Eigen::Matrix3d& K1,
                           const Eigen::Matrix3d& K2, const Sim3SolverOptions& options = {});

}  // namespace edgeslam
