#pragma once
// Fundamental matrix between two views: x2^T F21 x1 = 0 (homogeneous undistorted pixels).
// Normalised 8-point algorithm (Hartley-Zisserman alg. 11.1) with the rank-2 constraint, RANSAC on
// pre-drawn sets scored by symmetric point-to-epipolar-line distance.
#include <Eigen/Core>
#include <optional>
#include <span>

#include "geometry/ransac_sampling.h"
#include "geometry/two_view_score.h"

namespace edgeslam {

// Least-squares normalised 8-point from >= 8 matches; nullopt when degenerate.
// Throws std::invalid_argument on mismatched sizes or non-finite input.
std::optional<Eigen::Matrix3d> estimateFundamentalEightPoint(
    std::span<const Eigen::Vector2d> points1, std::span<const Eigen::Vector2d> points2);

// Point-to-epipolar-line distance in both images, gated at chi2::k1Dof95; each passing direction
// adds chi2::k2Dof95 - residual, so the score compares directly with scoreHomography().
TwoViewScore scoreFundamental(const Eigen::Matrix3d& F21, std::span<const Eigen::Vector2d> points1,
                              std::span<const Eigen::Vector2d> points2, double sigma_px);

struct FundamentalEstimate {
  bool valid = false;
  Eigen::Matrix3d F21 = Eigen::Matrix3d::Zero();
  TwoViewScore score;
};

// One model per sample set (its first eight indices), best score wins, then least-squares
// re-fits on the inliers while the score improves.
FundamentalEstimate findFundamentalRansac(std::span<const Eigen::Vector2d> points1,
                                          std::span<const Eigen::Vector2d> points2,
                                          const SampleSets& sample_sets, double sigma_px);

}  // namespace edgeslam
