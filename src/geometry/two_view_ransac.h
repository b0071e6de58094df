#pragma once
// The RANSAC loop shared by the homography and the fundamental matrix: one model per pre-drawn
// sample set, best score wins, then least-squares re-fits on the inliers while the score improves
// (the inlier set of one noisy minimal sample is refined into the model of the whole consensus).
#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "geometry/ransac_sampling.h"
#include "geometry/two_view_score.h"

namespace edgeslam {

struct TwoViewModelEstimate {
  bool valid = false;
  Eigen::Matrix3d model = Eigen::Matrix3d::Zero();
  TwoViewScore score;
};

// fit(indices) -> std::optional<Eigen::Matrix3d> in pixel coordinates; score(model) ->
// TwoViewScore.
template <typename Fit, typename Score>
TwoViewModelEstimate ransacWithRefit(std::size_t num_points, const SampleSets& sample_sets,
                                     int minimal_size, Fit&& fit, Score&& score) {
  constexpr int kMaxRefitRounds = 5;
  TwoViewModelEstimate best;
  for (int s = 0; s < sample_sets.count; ++s) {
    const std::optional<Eigen::Matrix3d> model =
        fit(std::span<const int>(sample_sets.set(s), static_cast<std::size_t>(minimal_size)));
    if (!model) continue;
    TwoViewScore candidate = score(*model);
    if (!best.valid || candidate.score > best.score.score) {
      best.valid = true;
      best.model = *model;
      best.score = std::move(candidate);
    }
  }
  if (!best.valid || best.score.num_inliers < minimal_size) return best;

  for (int round = 0; round < kMaxRefitRounds; ++round) {
    std::vector<int> inliers;
    for (std::size_t i = 0; i < num_points; ++i) {
      if (best.score.inliers[i]) inliers.push_back(static_cast<int>(i));
    }
    const std::optional<Eigen::Matrix3d> model = fit(std::span<const int>(inliers));
    if (!model) break;
    TwoViewScore candidate = score(*model);
    if (!(candidate.score > best.score.score)) break;
    best.model = *model;
    best.score = std::move(candidate);
  }
  return best;
}

}  // namespace edgeslam
