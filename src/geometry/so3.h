#pragma once
// Rotation exponential and logarithm on rotation vectors, shared by SE3 and Sim3.
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace edgeslam {

inline Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d m;
  m << 0.0, -v.z(), v.y(), v.z(), 0.0, -v.x(), -v.y(), v.x(), 0.0;
  return m;
}

inline Eigen::Quaterniond so3Exp(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  if (theta < 1e-10) {
    // First-order expansion keeps the result exact to double precision for tiny angles.
    return Eigen::Quaterniond(1.0, 0.5 * omega.x(), 0.5 * omega.y(), 0.5 * omega.z()).normalized();
  }
  return Eigen::Quaterniond(Eigen::AngleAxisd(theta, omega / theta));
}

inline Eigen::Vector3d so3Log(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() *= -1.0;  // shortest rotation, angle in [0, pi]
  const double sin_half = q.vec().norm();
  if (sin_half < 1e-10) return 2.0 * q.vec();
  const double theta = 2.0 * std::atan2(sin_half, q.w());
  return q.vec() * (theta / sin_half);
}

}  // namespace edgeslam
