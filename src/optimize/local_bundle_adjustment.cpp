#include "optimize/local_bundle_adjustment.h"

#include <ceres/loss_function.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <chrono>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "optimize/reprojection_costs.h"
#include "optimize/se3_manifold.h"

namespace edgeslam {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

void validateBundleAdjustmentProblem(const BundleAdjustmentProblem& problem,
                                     const std::string& caller) {
  problem.camera.validate();
  const auto fail = [&caller](const std::string& what) {
    throw std::invalid_argument(caller + ": " + what);
  };
  for (std::size_t i = 0; i < problem.keyframes.size(); ++i) {
    const SE3d& T = problem.keyframes[i].T_cw;
    if (!T.translation().allFinite() || !T.rotation().coeffs().allFinite()) {
      fail("keyframe " + std::to_string(i) + " (id " + std::to_string(problem.keyframes[i].id) +
           ") has a non-finite pose");
    }
  }
  for (std::size_t i = 0; i < problem.points.size(); ++i) {
    if (!problem.points[i].position.allFinite()) {
      fail("point " + std::to_string(i) + " (id " + std::to_string(problem.points[i].id) +
           ") is not finite");
    }
  }
  for (std::size_t i = 0; i < problem.observations.size(); ++i) {
    const BAObservation& o = problem.observations[i];
    const std::string name = "observation " + std::to_string(i) + ": ";
    if (o.keyframe >= problem.keyframes.size()) {
      fail(name + "keyframe index " + std::to_string(o.keyframe) + " out of range");
    }
    if (o.point >= problem.points.size()) {
      fail(name + "point index " + std::to_string(o.point) + " out of range");
    }
    if (!o.pixel.allFinite()) fail(name + "pixel is not finite");
    if (!(o.inv_sigma2 > 0.0) || !std::isfinite(o.inv_sigma2)) {
      fail(name + "inv_sigma2 must be positive, got " + std::to_string(o.inv_sigma2));
    }
    if (o.right_u && (!std::isfinite(*o.right_u) || !(problem.camera.bf > 0.0))) {
      fail(name + "stereo observation needs a finite right_u and a camera with bf > 0");
    }
  }
}

namespace {

class BundleSolver {
 public:
  BundleSolver(const BundleAdjustmentProblem& problem, const BundleAdjustmentOptions& options)
      : input_(problem),
        options_(options),
        mono_loss_(new ceres::HuberLoss(std::sqrt(options.chi2_mono)), ceres::TAKE_OWNERSHIP),
        stereo_loss_(new ceres::HuberLoss(std::sqrt(options.chi2_stereo)), ceres::TAKE_OWNERSHIP) {
    poses_.reserve(problem.keyframes.size());
    for (const BAKeyFrame& kf : problem.keyframes) poses_.push_back(toPoseBlock(kf.T_cw));
    points_.reserve(problem.points.size());
    for (const BAPoint& p : problem.points) points_.push_back(p.position);
    measurements_.reserve(problem.observations.size());
    for (const BAObservation& o : problem.observations) {
      measurements_.push_back({o.pixel, o.right_u.value_or(0.0), std::sqrt(o.inv_sigma2)});
    }
  }

  BundleAdjustmentResult run() {
    const Clock::time_point start = Clock::now();
    BundleAdjustmentResult result;
    result.rms_before = rms(/*inliers_only=*/false);
    if (cancelled()) {
      result.cancelled = true;
    } else {
      buildProblem();
      const bool more = solvePass(options_.first_pass_iterations, start, result);
      // Without outliers every residual lies in the quadratic zone of the kernel, so a converged
      // first pass is already the optimum of the second.
      if (more && options_.second_pass && !cancelled() &&
          (removeOutlierResiduals() > 0 || !last_pass_converged_)) {
        if (!options_.robust_in_second_pass) {
          mono_loss_.Reset(nullptr, ceres::TAKE_OWNERSHIP);
          stereo_loss_.Reset(nullptr, ceres::TAKE_OWNERSHIP);
        }
        solvePass(options_.second_pass_iterations, start, result);
      }
      result.cancelled = result.cancelled || cancelled();
    }
    for (std::size_t i = 0; i < input_.observations.size(); ++i) {
      if (isOutlier(i)) result.outliers.push_back(i);
    }
    result.rms_after = rms(/*inliers_only=*/true);
    result.T_cw.reserve(poses_.size());
    for (const PoseBlock& pose : poses_) result.T_cw.push_back(fromPoseBlock(pose));
    result.points = points_;
    return result;
  }

 private:
  bool cancelled() const { return options_.cancel != nullptr && options_.cancel->load(); }

  Eigen::Vector3d pointInCamera(std::size_t observation) const {
    const BAObservation& o = input_.observations[observation];
    return fromPoseBlock(poses_[o.keyframe]) * points_[o.point];
  }

  double chi2(std::size_t observation) const {
    const Eigen::Vector3d pc = pointInCamera(observation);
    return input_.observations[observation].right_u
               ? reprojectionChi2<kStereoResiduals>(input_.camera, pc, measurements_[observation])
               : reprojectionChi2<kMonoResiduals>(input_.camera, pc, measurements_[observation]);
  }

  bool isOutlier(std::size_t observation) const {
    const double threshold =
        input_.observations[observation].right_u ? options_.chi2_stereo : options_.chi2_mono;
    return !(chi2(observation) <= threshold);  // also true for infinity (not in front)
  }

  double rms(bool inliers_only) const {
    double sum = 0.0;
    std::size_t components = 0;
    for (std::size_t i = 0; i < input_.observations.size(); ++i) {
      const double c = chi2(i);
      if (!std::isfinite(c) || (inliers_only && isOutlier(i))) continue;
      sum += c;
      components += input_.observations[i].right_u ? kStereoResiduals : kMonoResiduals;
    }
    return components == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(components));
  }

  void buildProblem() {
    ceres::Problem::Options problem_options;
    problem_options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(problem_options);
    ordering_ = std::make_shared<ceres::ParameterBlockOrdering>();

    for (std::size_t i = 0; i < poses_.size(); ++i) {
      problem_->AddParameterBlock(poses_[i].data(), kPoseBlockSize, &manifold_);
      if (input_.keyframes[i].fixed) {
        problem_->SetParameterBlockConstant(poses_[i].data());
      } else {
        ++free_keyframes_;
      }
      ordering_->AddElementToGroup(poses_[i].data(), 1);
    }
    for (std::size_t i = 0; i < points_.size(); ++i) {
      problem_->AddParameterBlock(points_[i].data(), 3);
      if (input_.points[i].fixed) {
        problem_->SetParameterBlockConstant(points_[i].data());
      } else {
        ++free_points_;
      }
      ordering_->AddElementToGroup(points_[i].data(), 0);
    }

    costs_.resize(input_.observations.size());
    residual_ids_.assign(input_.observations.size(), nullptr);
    for (std::size_t i = 0; i < input_.observations.size(); ++i) {
      const BAObservation& o = input_.observations[i];
      // A point behind its camera cannot be evaluated; it is reported as an outlier at the end.
      if (!(pointInCamera(i).z() > kMinProjectionDepth)) continue;
      ceres::LossFunction* loss = nullptr;
      if (o.right_u) {
        costs_[i] = std::make_unique<BundleReprojectionCost<kStereoResiduals>>(input_.camera,
                                                                               measurements_[i]);
        loss = &stereo_loss_;
      } else {
        costs_[i] = std::make_unique<BundleReprojectionCost<kMonoResiduals>>(input_.camera,
                                                                             measurements_[i]);
        loss = &mono_loss_;
      }
      residual_ids_[i] = problem_->AddResidualBlock(
          costs_[i].get(), loss, poses_[o.keyframe].data(), points_[o.point].data());
    }
  }

  // Returns how many residual blocks were removed.
  int removeOutlierResiduals() {
    int removed = 0;
    for (std::size_t i = 0; i < residual_ids_.size(); ++i) {
      if (residual_ids_[i] != nullptr && isOutlier(i)) {
        problem_->RemoveResidualBlock(residual_ids_[i]);
        residual_ids_[i] = nullptr;
        ++removed;
      }
    }
    return removed;
  }

  // Returns false when the run must stop (cancelled, out of time, or the solver failed).
  bool solvePass(int max_iterations, Clock::time_point start, BundleAdjustmentResult& result) {
    if (problem_->NumResidualBlocks() == 0 || max_iterations <= 0) return true;
    ceres::Solver::Options solver_options;
    solver_options.max_num_iterations = max_iterations;
    solver_options.num_threads = options_.num_threads;
    solver_options.logging_type = ceres::SILENT;
    solver_options.minimizer_progress_to_stdout = false;
    if (free_points_ > 0 && free_keyframes_ > 0) {
      solver_options.linear_solver_type = free_keyframes_ <= options_.dense_schur_max_keyframes
                                              ? ceres::DENSE_SCHUR
                                              : ceres::SPARSE_SCHUR;
      solver_options.linear_solver_ordering = ordering_;
    } else {
      solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    }
    if (options_.max_time_s > 0.0) {
      const double left =
          options_.max_time_s - std::chrono::duration<double>(Clock::now() - start).count();
      if (left <= 0.0) {
        result.timed_out = true;
        return false;
      }
      solver_options.max_solver_time_in_seconds = left;
    }
    SolverControlCallback control(options_.cancel, options_.on_iteration, result.iterations);
    solver_options.callbacks.push_back(&control);

    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, problem_.get(), &summary);
    result.iterations = control.iterations();
    last_pass_converged_ = summary.termination_type == ceres::CONVERGENCE;
    if (control.cancelledDuringSolve()) result.cancelled = true;
    if (options_.max_time_s > 0.0 &&
        std::chrono::duration<double>(Clock::now() - start).count() >= options_.max_time_s) {
      result.timed_out = true;
    }
    return summary.IsSolutionUsable() && !result.cancelled && !result.timed_out;
  }

  const BundleAdjustmentProblem& input_;
  const BundleAdjustmentOptions& options_;
  std::vector<PoseBlock> poses_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<PixelMeasurement> measurements_;
  SE3LeftManifold manifold_;
  ceres::LossFunctionWrapper mono_loss_;
  ceres::LossFunctionWrapper stereo_loss_;
  std::vector<std::unique_ptr<ceres::CostFunction>> costs_;
  std::vector<ceres::ResidualBlockId> residual_ids_;
  std::unique_ptr<ceres::Problem> problem_;
  std::shared_ptr<ceres::ParameterBlockOrdering> ordering_;
  int free_keyframes_ = 0;
  int free_points_ = 0;
  bool last_pass_converged_ = false;
};

}  // namespace

BundleAdjustmentResult bundleAdjust(const BundleAdjustmentProblem& problem,
                                    const BundleAdjustmentOptions& options) {
  validateBundleAdjustmentProblem(problem, "bundleAdjust");
  return BundleSolver(problem, options).run();
}

}  // namespace edgeslam
