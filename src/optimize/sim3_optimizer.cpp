#include "optimize/sim3_optimizer.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string>

#include "geometry/sim3_scale.h"
#include "optimize/reprojection_error.h"
#include "optimize/sim3_parameters.h"

namespace edgeslam {
namespace {

// Reprojection of a point given in the other keyframe's camera frame: through S_12 into image 1
// (`inverse` false) or through S_12^-1 into image 2 (`inverse` true).
class Sim3ReprojectionCost {
 public:
  Sim3ReprojectionCost(const CameraProjection& camera, const Eigen::Vector3d& point_other,
                       const Eigen::Vector2d& pixel, double sigma_px, bool inverse)
      : camera_(camera),
        point_other_(point_other),
        pixel_(pixel),
        inv_sigma_(1.0 / sigma_px),
        inverse_(inverse) {}

  template <typename T>
  bool operator()(const T* rotation, const T* translation, const T* log_scale, T* residual) const {
    Sim3T<T> S_12 = Sim3T<T>::fromBlocks(rotation, translation, log_scale);
    if (inverse_) S_12 = S_12.inverse();
    const Eigen::Matrix<T, 3, 1> p = S_12 * point_other_.cast<T>();
    if (!(p.z() > T(kMinProjectionDepth))) return false;
    residual[0] = T(inv_sigma_) * (T(camera_.fx) * p.x() / p.z() + T(camera_.cx) - T(pixel_.x()));
    residual[1] = T(inv_sigma_) * (T(camera_.fy) * p.y() / p.z() + T(camera_.cy) - T(pixel_.y()));
    return true;
  }

  // The same error in plain doubles for the outlier test; infinity when behind the camera.
  double chi2(const Sim3d& S_12) const {
    const Eigen::Vector3d p = (inverse_ ? S_12.inverse() : S_12) * point_other_;
    if (!(p.z() > kMinProjectionDepth)) return std::numeric_limits<double>::infinity();
    return (inv_sigma_ * (camera_.project(p) - pixel_)).squaredNorm();
  }

 private:
  CameraProjection camera_;
  Eigen::Vector3d point_other_;
  Eigen::Vector2d pixel_;
  double inv_sigma_;
  bool inverse_;
};

struct MatchCosts {
  Sim3ReprojectionCost in_image1;
  Sim3ReprojectionCost in_image2;
};

void validate(std::span<const Sim3Match> matches) {
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const Sim3Match& m = matches[i];
    const std::string name = "refineSim3: match " + std::to_string(i) + ": ";
    if (!m.point1.allFinite() || !m.point2.allFinite() || !m.pixel1.allFinite() ||
        !m.pixel2.allFinite()) {
      throw std::invalid_argument(name + "non-finite point or pixel");
    }
    if (!(m.sigma1_px > 0.0) || !(m.sigma2_px > 0.0) || !std::isfinite(m.sigma1_px) ||
        !std::isfinite(m.sigma2_px)) {
      throw std::invalid_argument(name + "sigmas must be positive");
    }
  }
}

}  // namespace

Sim3RefinementResult refineSim3(const Sim3d& initial_S_12, std::span<const Sim3Match> matches,
                                const CameraProjection& camera1, const CameraProjection& camera2,
                                const Sim3RefinementOptions& options) {
  camera1.validate();
  camera2.validate();
  validate(matches);

  std::vector<MatchCosts> costs;
  costs.reserve(matches.size());
  for (const Sim3Match& m : matches) {
    costs.push_back({Sim3ReprojectionCost(camera1, m.point2, m.pixel1, m.sigma1_px, false),
                     Sim3ReprojectionCost(camera2, m.point1, m.pixel2, m.sigma2_px, true)});
  }

  Sim3RefinementResult result;
  Sim3d start = initial_S_12;
  bool fix_scale = options.fix_scale;
  if (!fix_scale && options.scale_from_ranges_below_baseline > 0.0) {
    const std::optional<double> baseline = cameraBaselineOverRange(start, matches);
    const bool views_meet =
        baseline.has_value() && *baseline < options.scale_from_ranges_below_baseline;
    const std::optional<double> scale = views_meet ? scaleFromRanges(start, matches) : std::nullopt;
    if (scale.has_value() && *scale > 0.0) {
      start = Sim3d(*scale, start.rotation(), start.translation());
      fix_scale = true;
      result.scale_from_ranges = true;
    }
  }
  result.S_12 = start;
  result.outliers = std::vector<bool>(matches.size(), false);
  Sim3Blocks blocks = Sim3Blocks::from(start);

  // Marks outliers at the current estimate; returns the inlier count.
  const auto classify = [&]() {
    const Sim3d S_12 = blocks.toSim3();
    int inliers = 0;
    for (std::size_t i = 0; i < costs.size(); ++i) {
      result.outliers[i] = !(costs[i].in_image1.chi2(S_12) <= options.chi2_threshold &&
                             costs[i].in_image2.chi2(S_12) <= options.chi2_threshold);
      if (!result.outliers[i]) ++inliers;
    }
    return inliers;
  };

  // One pass over the current inliers; points behind a camera at the start are left out.
  const auto solvePass = [&](int iterations, bool skip_outliers) {
    ceres::Problem::Options problem_options;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem problem(problem_options);
    ceres::EigenQuaternionManifold quaternion_manifold;
    ceres::HuberLoss loss(std::sqrt(options.chi2_threshold));
    const Sim3d S_12 = blocks.toSim3();
    for (std::size_t i = 0; i < costs.size(); ++i) {
      if (skip_outliers && result.outliers[i]) continue;
      for (const Sim3ReprojectionCost* cost : {&costs[i].in_image1, &costs[i].in_image2}) {
        if (!std::isfinite(cost->chi2(S_12))) continue;
        problem.AddResidualBlock(new ceres::AutoDiffCostFunction<Sim3ReprojectionCost, 2, 4, 3, 1>(
                                     new Sim3ReprojectionCost(*cost)),
                                 &loss, blocks.rotation.data(), blocks.translation.data(),
                                 &blocks.log_scale);
      }
    }
    if (problem.NumResidualBlocks() == 0) return;
    problem.SetManifold(blocks.rotation.data(), &quaternion_manifold);
    if (fix_scale) problem.SetParameterBlockConstant(&blocks.log_scale);
    ceres::Solver::Options solver_options;
    solver_options.linear_solver_type = ceres::DENSE_QR;
    solver_options.max_num_iterations = iterations;
    solver_options.num_threads = 1;
    solver_options.logging_type = ceres::SILENT;
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, &problem, &summary);
    result.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
  };

  solvePass(options.first_pass_iterations, false);
  result.inliers = classify();
  if (result.inliers < options.min_inliers) {
    result.S_12 = blocks.toSim3();
    return result;
  }
  solvePass(options.second_pass_iterations, true);
  result.inliers = classify();
  result.S_12 = blocks.toSim3();
  result.success = result.inliers >= options.min_inliers;
  return result;
}

}  // namespace edgeslam
