#include "optimize/pose_optimizer.h"

#include <ceres/loss_function.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "optimize/pose_batch_cost.h"
#include "optimize/reprojection_costs.h"
#include "optimize/se3_manifold.h"

namespace edgeslam {
namespace {

void validateObservations(std::span<const PoseObservation> observations,
                          const CameraProjection& camera) {
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const PoseObservation& o = observations[i];
    const auto fail = [i](const std::string& what) {
      throw std::invalid_argument("optimizePose: observation " + std::to_string(i) + ": " + what);
    };
    if (!o.point_world.allFinite()) fail("world point is not finite");
    if (!o.pixel.allFinite()) fail("pixel is not finite");
    if (!(o.inv_sigma2 > 0.0) || !std::isfinite(o.inv_sigma2)) {
      fail("inv_sigma2 must be positive, got " + std::to_string(o.inv_sigma2));
    }
    if (o.right_u) {
      if (!std::isfinite(*o.right_u)) fail("right_u is not finite");
      if (!(camera.bf > 0.0)) fail("stereo observation but the camera has no bf");
    }
  }
}

ceres::Problem::Options borrowingProblemOptions() {
  ceres::Problem::Options options;
  options.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  return options;
}

// The reference formulation: one residual block per observation, each with a ceres::HuberLoss;
// outliers stay in the problem with a zero residual.
struct PerObservationProblem {
  std::vector<std::unique_ptr<PoseReprojectionCost<kMonoResiduals>>> mono;
  std::vector<std::unique_ptr<PoseReprojectionCost<kStereoResiduals>>> stereo;
  ceres::LossFunctionWrapper mono_loss;
  ceres::LossFunctionWrapper stereo_loss;
  ceres::Problem problem;

  PerObservationProblem(std::span<const PoseObservation> observations,
                        const std::vector<PixelMeasurement>& measurements,
                        const CameraProjection& camera, const PoseOptimizerOptions& options,
                        PoseBlock& pose, SE3LeftManifold& manifold)
      : mono(observations.size()),
        stereo(observations.size()),
        mono_loss(new ceres::HuberLoss(std::sqrt(options.chi2_mono)), ceres::TAKE_OWNERSHIP),
        stereo_loss(new ceres::HuberLoss(std::sqrt(options.chi2_stereo)), ceres::TAKE_OWNERSHIP),
        problem(borrowingProblemOptions()) {
    problem.AddParameterBlock(pose.data(), kPoseBlockSize, &manifold);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      if (observations[i].right_u) {
        stereo[i] = std::make_unique<PoseReprojectionCost<kStereoResiduals>>(
            camera, observations[i].point_world, measurements[i]);
        problem.AddResidualBlock(stereo[i].get(), &stereo_loss, pose.data());
      } else {
        mono[i] = std::make_unique<PoseReprojectionCost<kMonoResiduals>>(
            camera, observations[i].point_world, measurements[i]);
        problem.AddResidualBlock(mono[i].get(), &mono_loss, pose.data());
      }
    }
  }

  void setActive(const std::vector<bool>& outliers) {
    for (std::size_t i = 0; i < outliers.size(); ++i) {
      if (mono[i]) mono[i]->setActive(!outliers[i]);
      if (stereo[i]) stereo[i]->setActive(!outliers[i]);
    }
  }
  void dropRobustLoss() {
    mono_loss.Reset(nullptr, ceres::TAKE_OWNERSHIP);
    stereo_loss.Reset(nullptr, ceres::TAKE_OWNERSHIP);
  }
};

}  // namespace

PoseOptimizerResult optimizePose(const SE3d& initial_T_cw,
                                 std::span<const PoseObservation> observations,
                                 const CameraProjection& camera,
                                 const PoseOptimizerOptions& options) {
  camera.validate();
  validateObservations(observations, camera);
  if (!initial_T_cw.translation().allFinite() || !initial_T_cw.rotation().coeffs().allFinite()) {
    throw std::invalid_argument("optimizePose: initial pose is not finite");
  }

  PoseOptimizerResult result{initial_T_cw, std::vector<bool>(observations.size(), false), 0, 0};
  PoseBlock pose = toPoseBlock(initial_T_cw);
  std::vector<PixelMeasurement> measurements(observations.size());
  for (std::size_t i = 0; i < observations.size(); ++i) {
    const PoseObservation& o = observations[i];
    measurements[i] = {o.pixel, o.right_u.value_or(0.0), std::sqrt(o.inv_sigma2)};
  }

  // Marks outliers at the current pose; returns the inlier count.
  const auto classify = [&]() {
    const SE3d T_cw = fromPoseBlock(pose);
    int inliers = 0;
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const Eigen::Vector3d pc = T_cw * observations[i].point_world;
      const bool stereo = observations[i].right_u.has_value();
      const double chi2 = stereo ? reprojectionChi2<kStereoResiduals>(camera, pc, measurements[i])
                                 : reprojectionChi2<kMonoResiduals>(camera, pc, measurements[i]);
      const bool outlier = !(chi2 <= (stereo ? options.chi2_stereo : options.chi2_mono));
      result.outliers[i] = outlier;
      if (!outlier) ++inliers;
    }
    return inliers;
  };

  // Points behind the camera cannot be evaluated at all; everything else starts as an inlier.
  {
    const SE3d T_cw = fromPoseBlock(pose);
    for (std::size_t i = 0; i < observations.size(); ++i) {
      const bool in_front = (T_cw * observations[i].point_world).z() > kMinProjectionDepth;
      result.outliers[i] = !in_front;
      if (in_front) ++result.inliers;
    }
  }
  if (result.inliers < options.min_inliers_to_continue || result.inliers == 0) {
    return result;
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver_options.num_threads = 1;
  solver_options.max_num_iterations = options.iterations_per_round;
  solver_options.logging_type = ceres::SILENT;
  solver_options.minimizer_progress_to_stdout = false;
  // Six well-conditioned unknowns: column scaling buys nothing and costs a pass over J.
  solver_options.jacobi_scaling = false;
  SE3LeftManifold manifold;
  std::unique_ptr<PerObservationProblem> per_observation;
  if (!options.single_residual_block) {
    per_observation = std::make_unique<PerObservationProblem>(observations, measurements, camera,
                                                              options, pose, manifold);
  }

  for (int round = 0; round < options.rounds; ++round) {
    const bool robust = round < options.rounds - 1 || options.robust_in_last_round;
    ceres::Solver::Summary summary;
    if (per_observation) {
      per_observation->setActive(result.outliers);
      if (!robust) per_observation->dropRobustLoss();
      ceres::Solve(solver_options, &per_observation->problem, &summary);
    } else {
      std::vector<PoseBatchTerm> active;
      active.reserve(static_cast<std::size_t>(result.inliers));
      for (std::size_t i = 0; i < observations.size(); ++i) {
        if (result.outliers[i]) continue;
        const bool stereo = observations[i].right_u.has_value();
        const double delta =
            robust ? std::sqrt(stereo ? options.chi2_stereo : options.chi2_mono) : 0.0;
        active.push_back({observations[i].point_world, measurements[i], stereo, delta});
      }
      PoseBatchReprojectionCost cost(camera, std::move(active));
      ceres::Problem problem(borrowingProblemOptions());
      problem.AddParameterBlock(pose.data(), kPoseBlockSize, &manifold);
      problem.AddResidualBlock(&cost, nullptr, pose.data());
      ceres::Solve(solver_options, &problem, &summary);
    }
    if (!summary.IsSolutionUsable()) break;
    result.iterations += summary.num_successful_steps + summary.num_unsuccessful_steps;
    const std::vector<bool> outliers_during_round = result.outliers;
    result.inliers = classify();
    if (result.inliers < options.min_inliers_to_continue) break;
    if (options.stop_when_stable && result.outliers == outliers_during_round) break;
  }
  result.T_cw = fromPoseBlock(pose);
  return result;
}

}  // namespace edgeslam
