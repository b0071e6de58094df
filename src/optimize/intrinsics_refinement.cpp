#include "optimize/intrinsics_refinement.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/loss_function.h>
#include <ceres/manifold.h>
#include <ceres/ordered_groups.h>
#include <ceres/problem.h>
#include <ceres/sized_cost_function.h>
#include <ceres/solver.h>
#include <fmt/format.h>

#include <array>
#include <cmath>
#include <memory>
#include <stdexcept>
#include <utility>

#include "optimize/reprojection_error.h"
#include "optimize/se3_manifold.h"
#include "optimize/solver_control.h"

namespace edgeslam {
namespace {

// Intrinsics block: [focal scale, k1, k2].
using IntrinsicsBlock = std::array<double, 3>;

struct RawModel {
  double fx, fy, cx, cy, p1, p2, k3, bf;
};

// Residual of one observation against the raw (distorted) keypoint; 2 components, or 3 with the
// disparity of a depth observation.
template <int kResiduals>
struct RawProjection {
  RawModel model;
  Eigen::Vector2d raw_pixel;
  double disparity = 0.0;  // bf / depth as stored, for kStereoResiduals
  double weight = 1.0;     // 1 / sigma

  template <typename T>
  bool operator()(const T* pc, const T* theta, T* residual) const {
    if (!(pc[2] > T(kMinProjectionDepth))) return false;
    const T x = pc[0] / pc[2];
    const T y = pc[1] / pc[2];
    const T r2 = x * x + y * y;
    const T radial = T(1) + theta[1] * r2 + theta[2] * r2 * r2 + T(model.k3) * r2 * r2 * r2;
    const T xd = x * radial + T(2 * model.p1) * x * y + T(model.p2) * (r2 + T(2) * x * x);
    const T yd = y * radial + T(model.p1) * (r2 + T(2) * y * y) + T(2 * model.p2) * x * y;
    residual[0] = T(weight) * (theta[0] * T(model.fx) * xd + T(model.cx) - T(raw_pixel.x()));
    residual[1] = T(weight) * (theta[0] * T(model.fy) * yd + T(model.cy) - T(raw_pixel.y()));
    if constexpr (kResiduals == kStereoResiduals) {
      residual[2] = T(weight) * theta[0] * (T(model.bf) / pc[2] - T(disparity));
    }
    return true;
  }
};

// Pose (SE3 block, tangent Jacobian in the first 6 columns as se3_manifold.h requires), world
// point and intrinsics; the projection's derivatives come from automatic differentiation.
template <int kResiduals>
class IntrinsicsReprojectionCost final
    : public ceres::SizedCostFunction<kResiduals, kPoseBlockSize, 3, 3> {
 public:
  explicit IntrinsicsReprojectionCost(const RawProjection<kResiduals>& projection)
      : projection_(projection), inner_(new RawProjection<kResiduals>(projection)) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
    const Eigen::Vector3d t(parameters[0][4], parameters[0][5], parameters[0][6]);
    const Eigen::Map<const Eigen::Vector3d> point_world(parameters[1]);
    const Eigen::Vector3d pc = q * point_world + t;
    if (jacobians == nullptr) return projection_(pc.data(), parameters[2], residuals);

    using RowMajor3 = Eigen::Matrix<double, kResiduals, 3, Eigen::RowMajor>;
    RowMajor3 d_pc;
    const double* inner_parameters[2] = {pc.data(), parameters[2]};
    double* inner_jacobians[2] = {d_pc.data(), jacobians[2]};
    if (!inner_.Evaluate(inner_parameters, residuals, inner_jacobians)) return false;
    if (jacobians[0] != nullptr) {
      Eigen::Map<Eigen::Matrix<double, kResiduals, kPoseBlockSize, Eigen::RowMajor>> j(
          jacobians[0]);
      j.template leftCols<kPoseTangentSize>().noalias() = d_pc * pointJacobianWrtLeftPose(pc);
      j.col(kPoseTangentSize).setZero();
    }
    if (jacobians[1] != nullptr) {
      Eigen::Map<RowMajor3>(jacobians[1]).noalias() = d_pc * q.toRotationMatrix();
    }
    return true;
  }

 private:
  RawProjection<kResiduals> projection_;
  ceres::AutoDiffCostFunction<RawProjection<kResiduals>, kResiduals, 3, 3> inner_;
};

class IntrinsicsSolver {
 public:
  IntrinsicsSolver(const BundleAdjustmentProblem& problem, const PinholeCamera& camera,
                   const IntrinsicsRefinementOptions& options)
      : input_(problem),
        options_(options),
        input_camera_intrinsics_(camera.intrinsics()),
        loss_mono_(std::make_unique<ceres::HuberLoss>(std::sqrt(kChi2Mono95))),
        loss_stereo_(std::make_unique<ceres::HuberLoss>(std::sqrt(kChi2Stereo95))) {
    const Distortion& d = camera.intrinsics().distortion;
    model_ = {camera.fx(), camera.fy(), camera.cx(), camera.cy(),
              d.p1,        d.p2,        d.k3,        problem.camera.bf};
    intrinsics_ = {1.0, d.k1, d.k2};
    for (const BAKeyFrame& kf : problem.keyframes) poses_.push_back(toPoseBlock(kf.T_cw));
    for (const BAPoint& p : problem.points) points_.push_back(p.position);
    for (const BAObservation& o : problem.observations) {
      const Eigen::Vector2d raw = camera.hasDistortion() ? camera.distort(o.pixel) : o.pixel;
      const double weight = std::sqrt(o.inv_sigma2);
      if (o.right_u) {
        stereo_.emplace_back(
            RawProjection<kStereoResiduals>{model_, raw, o.pixel.x() - *o.right_u, weight});
      } else {
        mono_.emplace_back(RawProjection<kMonoResiduals>{model_, raw, 0.0, weight});
      }
      index_.push_back(o.right_u ? -static_cast<long>(stereo_.size())
                                 : static_cast<long>(mono_.size()));
    }
  }

  IntrinsicsRefinementResult run() {
    IntrinsicsRefinementResult result;
    buildProblem();
    // Passes 1 and 2: the given intrinsics, the second without the first's outliers. Their RMS is
    // what the refined intrinsics must beat.
    problem_->SetParameterBlockConstant(intrinsics_.data());
    if (!solve(result) || (removeOutliers(), !solve(result))) return abandoned(result);
    const double rms_fixed = rms();
    const auto poses_fixed = poses_;
    const auto points_fixed = points_;
    // Pass 3: the intrinsics free as well.
    problem_->SetParameterBlockVariable(intrinsics_.data());
    if (!solve(result)) return abandoned(result);
    // Judged on the same observations as the fixed intrinsics.
    const double rms_refined = rms();

    result.rms_before = rms_fixed;
    result.rms_after = rms_refined;
    const double gain = rms_fixed > 0.0 ? 1.0 - rms_refined / rms_fixed : 0.0;
    const double given_k1 = input_camera_intrinsics_.distortion.k1;
    const double given_k2 = input_camera_intrinsics_.distortion.k2;
    if (std::abs(intrinsics_[0] - 1.0) > options_.max_focal_change) {
      result.reason =
          fmt::format("focal length change {:+.1f} % beyond the allowed {:.0f} %",
                      100.0 * (intrinsics_[0] - 1.0), 100.0 * options_.max_focal_change);
    } else if (std::abs(intrinsics_[1] - given_k1) > options_.max_distortion_change ||
               std::abs(intrinsics_[2] - given_k2) > options_.max_distortion_change) {
      result.reason = fmt::format(
          "distortion change k1 {:+.3f} k2 {:+.3f} beyond the allowed {:.2f}",
          intrinsics_[1] - given_k1, intrinsics_[2] - given_k2, options_.max_distortion_change);
    } else if (gain < options_.min_rms_gain) {
      result.reason = fmt::format(
          "the data does not ask for it (reprojection RMS {:.2f} % lower, under {:.2f} %)",
          100.0 * gain, 100.0 * options_.min_rms_gain);
    } else {
      result.adopted = true;
      if (readmitInliers() > 0) {
        removeOutliers();
        if (!solve(result)) return abandoned(result);
      }
    }
    // After the last solve when adopted: the refined values; otherwise what the data asked for.
    result.focal_scale = intrinsics_[0];
    result.estimate = refinedIntrinsics();
    result.intrinsics = result.adopted ? result.estimate : input_camera_intrinsics_;
    for (const ceres::ResidualBlockId id : residual_ids_) result.inliers += id != nullptr ? 1 : 0;
    result.outliers = input_.observations.size() - result.inliers;
    const auto& poses = result.adopted ? poses_ : poses_fixed;
    const auto& points = result.adopted ? points_ : points_fixed;
    for (const PoseBlock& pose : poses) result.T_cw.push_back(fromPoseBlock(pose));
    result.points = points;
    return result;
  }

 private:
  IntrinsicsRefinementResult abandoned(IntrinsicsRefinementResult& result) {
    result.adopted = false;
    result.reason = "the solver stopped (cancelled or failed)";
    result.intrinsics = result.estimate = input_camera_intrinsics_;
    for (const BAKeyFrame& kf : input_.keyframes) result.T_cw.push_back(kf.T_cw);
    for (const BAPoint& p : input_.points) result.points.push_back(p.position);
    return result;
  }

  CameraIntrinsics refinedIntrinsics() const {
    CameraIntrinsics refined = input_camera_intrinsics_;
    refined.fx *= intrinsics_[0];
    refined.fy *= intrinsics_[0];
    refined.distortion.k1 = intrinsics_[1];
    refined.distortion.k2 = intrinsics_[2];
    return refined;
  }

  template <int kResiduals>
  double chi2(const RawProjection<kResiduals>& projection, std::size_t observation) const {
    const BAObservation& o = input_.observations[observation];
    const Eigen::Vector3d pc = fromPoseBlock(poses_[o.keyframe]) * points_[o.point];
    Eigen::Matrix<double, kResiduals, 1> r;
    if (!projection(pc.data(), intrinsics_.data(), r.data())) {
      return std::numeric_limits<double>::infinity();
    }
    return r.squaredNorm();
  }

  double chi2(std::size_t observation) const {
    const long k = index_[observation];
    return k < 0 ? chi2(stereo_[static_cast<std::size_t>(-k - 1)], observation)
                 : chi2(mono_[static_cast<std::size_t>(k - 1)], observation);
  }

  void buildProblem() {
    ceres::Problem::Options problem_options;
    problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    problem_ = std::make_unique<ceres::Problem>(problem_options);
    for (std::size_t i = 0; i < poses_.size(); ++i) {
      problem_->AddParameterBlock(poses_[i].data(), kPoseBlockSize, &pose_manifold_);
      if (input_.keyframes[i].fixed) problem_->SetParameterBlockConstant(poses_[i].data());
    }
    for (std::size_t i = 0; i < points_.size(); ++i) {
      problem_->AddParameterBlock(points_[i].data(), 3);
      if (input_.points[i].fixed) problem_->SetParameterBlockConstant(points_[i].data());
    }
    std::vector<int> held;
    if (!options_.refine_focal) held.push_back(0);
    if (!options_.refine_k1) held.push_back(1);
    if (!options_.refine_k2) held.push_back(2);
    problem_->AddParameterBlock(intrinsics_.data(), 3);
    if (!held.empty()) {
      intrinsics_manifold_ = std::make_unique<ceres::SubsetManifold>(3, held);
      problem_->SetManifold(intrinsics_.data(), intrinsics_manifold_.get());
    }

    residual_ids_.assign(input_.observations.size(), nullptr);
    for (std::size_t i = 0; i < input_.observations.size(); ++i) {
      if (std::isfinite(chi2(i))) addResidual(i);  // behind its camera: left out
    }
  }

  void addResidual(std::size_t i) {
    const BAObservation& o = input_.observations[i];
    const long k = index_[i];
    ceres::CostFunction* cost = nullptr;
    ceres::LossFunction* loss = nullptr;
    if (k < 0) {
      cost = new IntrinsicsReprojectionCost<kStereoResiduals>(
          stereo_[static_cast<std::size_t>(-k - 1)]);
      loss = loss_stereo_.get();
    } else {
      cost = new IntrinsicsReprojectionCost<kMonoResiduals>(mono_[static_cast<std::size_t>(k - 1)]);
      loss = loss_mono_.get();
    }
    residual_ids_[i] = problem_->AddResidualBlock(cost, loss, poses_[o.keyframe].data(),
                                                  points_[o.point].data(), intrinsics_.data());
  }

  bool isInlier(std::size_t i) const {
    return chi2(i) <= (index_[i] < 0 ? kChi2Stereo95 : kChi2Mono95);
  }

  // Observations the old intrinsics rejected (often those near the border, which carry most of
  // the distortion) come back once the refined ones explain them. Returns how many.
  int readmitInliers() {
    int readmitted = 0;
    for (std::size_t i = 0; i < residual_ids_.size(); ++i) {
      if (residual_ids_[i] == nullptr && isInlier(i)) {
        addResidual(i);
        ++readmitted;
      }
    }
    return readmitted;
  }

  void removeOutliers() {
    for (std::size_t i = 0; i < residual_ids_.size(); ++i) {
      if (residual_ids_[i] == nullptr) continue;
      if (!isInlier(i)) {
        problem_->RemoveResidualBlock(residual_ids_[i]);
        residual_ids_[i] = nullptr;
      }
    }
  }

  // Points first (eliminated by the Schur complement), then poses and intrinsics. Made anew for
  // each solve: Ceres drops the constant blocks from the ordering it is given.
  std::shared_ptr<ceres::ParameterBlockOrdering> makeOrdering() {
    auto ordering = std::make_shared<ceres::ParameterBlockOrdering>();
    for (PoseBlock& pose : poses_) ordering->AddElementToGroup(pose.data(), 1);
    for (Eigen::Vector3d& point : points_) ordering->AddElementToGroup(point.data(), 0);
    ordering->AddElementToGroup(intrinsics_.data(), 1);
    return ordering;
  }

  // RMS per residual component over the observations still in the problem.
  double rms() const {
    double sum = 0.0;
    std::size_t components = 0;
    for (std::size_t i = 0; i < residual_ids_.size(); ++i) {
      if (residual_ids_[i] == nullptr) continue;
      const double c = chi2(i);
      if (!std::isfinite(c)) continue;
      sum += c;
      components += index_[i] < 0 ? kStereoResiduals : kMonoResiduals;
    }
    return components == 0 ? 0.0 : std::sqrt(sum / static_cast<double>(components));
  }

  bool solve(IntrinsicsRefinementResult& result) {
    if (problem_->NumResidualBlocks() == 0) return false;
    ceres::Solver::Options solver_options;
    solver_options.max_num_iterations = options_.iterations;
    solver_options.linear_solver_type = ceres::SPARSE_SCHUR;
    solver_options.linear_solver_ordering = makeOrdering();
    solver_options.logging_type = ceres::SILENT;
    SolverControlCallback control(options_.cancel, {}, result.iterations);
    solver_options.callbacks.push_back(&control);
    ceres::Solver::Summary summary;
    ceres::Solve(solver_options, problem_.get(), &summary);
    result.iterations = control.iterations();

    return summary.IsSolutionUsable() && !control.cancelledDuringSolve();
  }

  const BundleAdjustmentProblem& input_;
  const IntrinsicsRefinementOptions& options_;
  CameraIntrinsics input_camera_intrinsics_;
  RawModel model_{};
  IntrinsicsBlock intrinsics_{};
  std::vector<PoseBlock> poses_;
  std::vector<Eigen::Vector3d> points_;
  std::vector<RawProjection<kMonoResiduals>> mono_;
  std::vector<RawProjection<kStereoResiduals>> stereo_;
  std::vector<long> index_;  // per observation: k > 0 mono_[k - 1], k < 0 stereo_[-k - 1]
  std::unique_ptr<ceres::LossFunction> loss_mono_;
  std::unique_ptr<ceres::LossFunction> loss_stereo_;
  SE3LeftManifold pose_manifold_;
  std::unique_ptr<ceres::Manifold> intrinsics_manifold_;
  std::unique_ptr<ceres::Problem> problem_;
  std::vector<ceres::ResidualBlockId> residual_ids_;
};

}  // namespace

std::optional<IntrinsicsRefinementOptions> parseRefinedIntrinsics(
    std::string_view spec, IntrinsicsRefinementOptions base) {
  IntrinsicsRefinementOptions options = std::move(base);
  options.refine_focal = options.refine_k1 = options.refine_k2 = false;
  if (spec == "off") return options;
  while (true) {
    const std::size_t comma = spec.find(',');
    const std::string_view name = spec.substr(0, comma);
    bool* flag = name == "focal" ? &options.refine_focal
                 : name == "k1"  ? &options.refine_k1
                 : name == "k2"  ? &options.refine_k2
                                 : nullptr;
    if (flag == nullptr || *flag) return std::nullopt;  // unknown or repeated
    *flag = true;
    if (comma == std::string_view::npos) return options;
    spec.remove_prefix(comma + 1);
  }
}

bool refinesAnything(const IntrinsicsRefinementOptions& options) {
  return options.refine_focal || options.refine_k1 || options.refine_k2;
}

IntrinsicsRefinementResult refineIntrinsics(const BundleAdjustmentProblem& problem,
                                            const PinholeCamera& camera,
                                            const IntrinsicsRefinementOptions& options) {
  validateBundleAdjustmentProblem(problem, "refineIntrinsics");
  if (!refinesAnything(options)) {
    throw std::invalid_argument("refineIntrinsics: nothing to refine (focal, k1 and k2 all off)");
  }
  if (options.iterations <= 0) {
    throw std::invalid_argument("refineIntrinsics: iterations must be positive");
  }
  std::size_t free_keyframes = 0;
  for (const BAKeyFrame& kf : problem.keyframes) free_keyframes += kf.fixed ? 0 : 1;
  if (free_keyframes < options.min_keyframes) {
    IntrinsicsRefinementResult result;
    result.reason = "too few keyframes (" + std::to_string(free_keyframes) + ")";
    result.intrinsics = result.estimate = camera.intrinsics();
    for (const BAKeyFrame& kf : problem.keyframes) result.T_cw.push_back(kf.T_cw);
    for (const BAPoint& p : problem.points) result.points.push_back(p.position);
    return result;
  }
  return IntrinsicsSolver(problem, camera, options).run();
}

}  // namespace edgeslam
