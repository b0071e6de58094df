#pragma once
// SE3 poses as Ceres parameter blocks: 7 doubles [qx qy qz qw tx ty tz] (Eigen's quaternion
// coefficient order, then the translation), updated on the left: T <- exp(delta) * T with the
// tangent delta = [rho; phi] of SE3d::exp.
//
// Speed trick: PlusJacobian is [I6; 0], so the cost functions of this part write their Jacobian
// with respect to the tangent delta into the first 6 of their 7 ambient columns (the 7th is zero)
// and Ceres' product J_ambient * PlusJacobian is exactly the tangent Jacobian. Cost functions that
// use this manifold must follow that convention (automatic differentiation through the quaternion
// would not).
#include <ceres/manifold.h>

#include <array>

#include "geometry/se3.h"

namespace edgeslam {

inline constexpr int kPoseBlockSize = 7;
inline constexpr int kPoseTangentSize = 6;
using PoseBlock = std::array<double, kPoseBlockSize>;

PoseBlock toPoseBlock(const SE3d& pose);
SE3d fromPoseBlock(const double* block);
inline SE3d fromPoseBlock(const PoseBlock& block) {
  return fromPoseBlock(block.data());
}

class SE3LeftManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return kPoseBlockSize; }
  int TangentSize() const override { return kPoseTangentSize; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool RightMultiplyByPlusJacobian(const double* x, int num_rows, const double* ambient_matrix,
                                   double* tangent_matrix) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace edgeslam
