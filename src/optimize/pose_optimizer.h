#pragma once
// Pose-only optimisation (motion-only bundle adjustment) for tracking: refines the camera pose
// T_cw against fixed world points, classifying each observation as inlier or outlier.
#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "geometry/se3.h"
#include "optimize/camera_projection.h"
#include "optimize/chi2_thresholds.h"

namespace edgeslam {

struct PoseObservation {
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted keypoint
  std::optional<double> right_u;  // stereo / RGB-D virtual right coordinate u - bf / depth
  double inv_sigma2 = 1.0;        // information of the keypoint's pyramid level
};

struct PoseOptimizerOptions {
  // Rounds of (optimise, classify); outliers of a round are left out of the next, and come back
  // when their error falls under the threshold again.
  int rounds = 4;
  int iterations_per_round = 10;
  double chi2_mono = kChi2Mono95;
  double chi2_stereo = kChi2Stereo95;
  // The Huber kernel protects against outliers not yet classified; the last round runs without it.
  bool robust_in_last_round = false;
  // Stop classifying once fewer inliers than this remain (the pose is then not trustworthy).
  int min_inliers_to_continue = 10;
  // Stop early when a round leaves the inlier set unchanged: every active residual is then inside
  // the quadratic zone of the kernel, so further rounds (with or without it) start at their
  // optimum.
  bool stop_when_stable = true;
  // All active observations in one compressed residual block (pose_batch_cost.h), rebuilt each
  // round: the same cost, gradient and steps as one block per observation, ~3.5x faster. false:
  // one block per observation with a ceres::HuberLoss each (the reference the benchmark and the
  // tests compare with).
  bool single_residual_block = true;
};

struct PoseOptimizerResult {
  SE3d T_cw;
  std::vector<bool> outliers;  // one per observation
  int inliers = 0;
  int iterations = 0;  // solver iterations over all rounds
};

// Throws std::invalid_argument for a bad camera or observation (naming its index).
PoseOptimizerResult optimizePose(const SE3d& initial_T_cw,
                                 std::span<const PoseObservation> observations,
                                 const CameraProjection& camera,
                                 const PoseOptimizerOptions& options = {});

}  // namespace edgeslam
