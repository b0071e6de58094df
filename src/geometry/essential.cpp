#include "geometry/essential.h"

#include <Eigen/SVD>

namespace edgeslam {

Eigen::Matrix3d essentialFromFundamental(const Eigen::Matrix3d& F21, const Eigen::Matrix3d& K1,
                                         const Eigen::Matrix3d& K2) {
  return K2.transpose() * F21 * K1;
}

std::array<SE3d, 4> decomposeEssential(const Eigen::Matrix3d& E21) {
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(E21, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d U = svd.matrixU();
  Eigen::Matrix3d V = svd.matrixV();
  // E is defined up to sign, so U and V may be flipped to make both proper rotations.
  if (U.determinant() < 0.0) U = -U;
  if (V.determinant() < 0.0) V = -V;
  Eigen::Matrix3d W;
  W << 0.0, -1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 1.0;
  const Eigen::Matrix3d Ra = U * W * V.transpose();
  const Eigen::Matrix3d Rb = U * W.transpose() * V.transpose();
  const Eigen::Vector3d t = U.col(2).normalized();
  return {SE3d(Ra, t), SE3d(Ra, -t), SE3d(Rb, t), SE3d(Rb, -t)};
}

}  // namespace edgeslam
