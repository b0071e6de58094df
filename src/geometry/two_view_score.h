#pragma once
// Score of a two-view model (homography or fundamental matrix) on a set of matches, as used for
// RANSAC and for choosing between the two models: each direction whose squared residual
// (in units of sigma^2) is below the model's threshold adds (chi2::k2Dof95 - residual); matches
// whose residuals pass in both directions are inliers. A shared offset (the homography's
// threshold) keeps the scores of both models on one scale.
#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

namespace edgeslam {

struct TwoViewScore {
  double score = 0.0;
  int num_inliers = 0;
  std::vector<char> inliers;  // one flag per match
};

// Throws std::invalid_argument naming `who` when the two sets differ in size or hold a
// non-finite coordinate.
void requireMatchedPoints(std::span<const Eigen::Vector2d> points1,
                          std::span<const Eigen::Vector2d> points2, const char* who);

// Unit-norm null vector of A (smallest right singular vector); A has 9 columns and >= 8 rows.
// nullopt when the null space has more than one dimension (degenerate configuration).
std::optional<Eigen::Matrix<double, 9, 1>> nullVector9(
    const Eigen::Matrix<double, Eigen::Dynamic, 9>& A);

}  // namespace edgeslam
