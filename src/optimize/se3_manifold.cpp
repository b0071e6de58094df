#include "optimize/se3_manifold.h"

#include <Eigen/Core>
#include <algorithm>

namespace edgeslam {

PoseBlock toPoseBlock(const SE3d& pose) {
  const Eigen::Quaterniond& q = pose.rotation();
  const Eigen::Vector3d& t = pose.translation();
  return {q.x(), q.y(), q.z(), q.w(), t.x(), t.y(), t.z()};
}

SE3d fromPoseBlock(const double* block) {
  return {Eigen::Quaterniond(block[3], block[0], block[1], block[2]),
          Eigen::Vector3d(block[4], block[5], block[6])};
}

bool SE3LeftManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const Vector6d xi = Eigen::Map<const Vector6d>(delta);
  const PoseBlock result = toPoseBlock(SE3d::exp(xi) * fromPoseBlock(x));
  std::copy(result.begin(), result.end(), x_plus_delta);
  return true;
}

bool SE3LeftManifold::PlusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, kPoseBlockSize, kPoseTangentSize, Eigen::RowMajor>> j(jacobian);
  j.setZero();
  j.topRows<kPoseTangentSize>().setIdentity();
  return true;
}

bool SE3LeftManifold::RightMultiplyByPlusJacobian(const double* /*x*/, int num_rows,
                                                  const double* ambient_matrix,
                                                  double* tangent_matrix) const {
  for (int row = 0; row < num_rows; ++row) {
    std::copy_n(ambient_matrix + row * kPoseBlockSize, kPoseTangentSize,
                tangent_matrix + row * kPoseTangentSize);
  }
  return true;
}

bool SE3LeftManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<Vector6d> out(y_minus_x);
  out = (fromPoseBlock(y) * fromPoseBlock(x).inverse()).log();
  return true;
}

bool SE3LeftManifold::MinusJacobian(const double* /*x*/, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, kPoseTangentSize, kPoseBlockSize, Eigen::RowMajor>> j(jacobian);
  j.setZero();
  j.leftCols<kPoseTangentSize>().setIdentity();
  return true;
}

}  // namespace edgeslam
