#pragma once
// Analytic Ceres cost functions of keypoint reprojections against SE3 pose blocks (see
// se3_manifold.h for the block layout and the Jacobian convention).
#include <ceres/sized_cost_function.h>

#include <Eigen/Core>

#include "optimize/reprojection_error.h"
#include "optimize/se3_manifold.h"

namespace edgeslam {

namespace reprojection_detail {

template <int kResiduals>
void writePoseJacobian(const Eigen::Matrix<double, kResiduals, 3>& d_r_d_pc,
                       const Eigen::Vector3d& pc, double* jacobian) {
  Eigen::Map<Eigen::Matrix<double, kResiduals, kPoseBlockSize, Eigen::RowMajor>> j(jacobian);
  j.template leftCols<kPoseTangentSize>().noalias() = d_r_d_pc * pointJacobianWrtLeftPose(pc);
  j.col(kPoseTangentSize).setZero();
}

}  // namespace reprojection_detail

// Pose-only: the world point is fixed. Inactive observations (outliers between rounds of
// classification) contribute a zero residual without being removed from the problem.
template <int kResiduals>
class PoseReprojectionCost final : public ceres::SizedCostFunction<kResiduals, kPoseBlockSize> {
 public:
  PoseReprojectionCost(const CameraProjection& camera, const Eigen::Vector3d& point_world,
                       const PixelMeasurement& measurement)
      : camera_(camera), point_world_(point_world), measurement_(measurement) {}

  void setActive(bool active) { active_ = active; }
  bool active() const { return active_; }

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    if (!active_) {
      Eigen::Map<Eigen::Matrix<double, kResiduals, 1>>(residuals).setZero();
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        Eigen::Map<Eigen::Matrix<double, kResiduals, kPoseBlockSize>>(jacobians[0]).setZero();
      }
      return true;
    }
    const double* x = parameters[0];
    const Eigen::Map<const Eigen::Quaterniond> q(x);
    const Eigen::Vector3d pc = q * point_world_ + Eigen::Vector3d(x[4], x[5], x[6]);
    const bool want_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
    Eigen::Matrix<double, kResiduals, 3> d_r_d_pc;
    if (!whitenedReprojection<kResiduals>(camera_, pc, measurement_, residuals,
                                          want_jacobian ? &d_r_d_pc : nullptr)) {
      return false;
    }
    if (want_jacobian)
      reprojection_detail::writePoseJacobian<kResiduals>(d_r_d_pc, pc, jacobians[0]);
    return true;
  }

 private:
  CameraProjection camera_;
  Eigen::Vector3d point_world_;
  PixelMeasurement measurement_;
  bool active_ = true;
};

// Bundle adjustment: pose block (7) and world point block (3) are both variables.
template <int kResiduals>
class BundleReprojectionCost final
    : public ceres::SizedCostFunction<kResiduals, kPoseBlockSize, 3> {
 public:
  BundleReprojectionCost(const CameraProjection& camera, const PixelMeasurement& measurement)
      : camera_(camera), measurement_(measurement) {}

  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override {
    const double* x = parameters[0];
    const Eigen::Map<const Eigen::Quaterniond> q(x);
    const Eigen::Map<const Eigen::Vector3d> point_world(parameters[1]);
    const Eigen::Vector3d pc = q * point_world + Eigen::Vector3d(x[4], x[5], x[6]);
    const bool want_pose = jacobians != nullptr && jacobians[0] != nullptr;
    const bool want_point = jacobians != nullptr && jacobians[1] != nullptr;
    Eigen::Matrix<double, kResiduals, 3> d_r_d_pc;
    if (!whitenedReprojection<kResiduals>(camera_, pc, measurement_, residuals,
                                          (want_pose || want_point) ? &d_r_d_pc : nullptr)) {
      return false;
    }
    if (want_pose) reprojection_detail::writePoseJacobian<kResiduals>(d_r_d_pc, pc, jacobians[0]);
    if (want_point) {
      Eigen::Map<Eigen::Matrix<double, kResiduals, 3, Eigen::RowMajor>>(jacobians[1]).noalias() =
          d_r_d_pc * q.toRotationMatrix();
    }
    return true;
  }

 private:
  CameraProjection camera_;
  PixelMeasurement measurement_;
};

}  // namespace edgeslam
