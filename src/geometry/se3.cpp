#include "geometry/se3.h"

#include <Eigen/SVD>
#include <cmath>

#include "geometry/so3.h"

namespace edgeslam {
namespace {

Eigen::Matrix3d nearestRotation(const Eigen::Matrix3d& m) {
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(m, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d r = svd.matrixU() * svd.matrixV().transpose();
  if (r.determinant() < 0.0) {
    Eigen::Matrix3d u = svd.matrixU();
    u.col(2) *= -1.0;
    r = u * svd.matrixV().transpose();
  }
  return r;
}

// Left Jacobian of SO(3): maps the translation tangent rho to the group translation.
Eigen::Matrix3d so3LeftJacobian(const Eigen::Vector3d& omega) {
  const double theta = omega.norm();
  const Eigen::Matrix3d w = skew(omega);
  if (theta < 1e-8) return Eigen::Matrix3d::Identity() + 0.5 * w + w * w / 6.0;
  const double t2 = theta * theta;
  return Eigen::Matrix3d::Identity() + (1.0 - std::cos(theta)) / t2 * w +
         (theta - std::sin(theta)) / (t2 * theta) * w * w;
}

}  // namespace

SE3d::SE3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation)
    : rotation_(Eigen::Quaterniond(nearestRotation(rotation)).normalized()),
      translation_(translation) {}

SE3d SE3d::fromMatrix(const Eigen::Matrix4d& m) {
  return {Eigen::Matrix3d(m.topLeftCorner<3, 3>()), Eigen::Vector3d(m.topRightCorner<3, 1>())};
}

SE3d SE3d::fromMatrix3x4(const Eigen::Matrix<double, 3, 4>& m) {
  return {Eigen::Matrix3d(m.leftCols<3>()), Eigen::Vector3d(m.col(3))};
}

SE3d SE3d::exp(const Vector6d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d omega = xi.tail<3>();
  return {so3Exp(omega), so3LeftJacobian(omega) * rho};
}

Vector6d SE3d::log() const {
  const Eigen::Vector3d omega = so3Log(rotation_);
  Vector6d xi;
  xi.head<3>() = so3LeftJacobian(omega).inverse() * translation_;
  xi.tail<3>() = omega;
  return xi;
}

SE3d SE3d::inverse() const {
  const Eigen::Quaterniond r_inv = rotation_.conjugate();
  return {r_inv, -(r_inv * translation_)};
}

Eigen::Matrix4d SE3d::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = rotationMatrix();
  m.topRightCorner<3, 1>() = translation_;
  return m;
}

Eigen::Matrix<double, 3, 4> SE3d::matrix3x4() const {
  return matrix().topRows<3>();
}

double rotationDistance(const SE3d& a, const SE3d& b) {
  return so3Log(a.rotation() * b.rotation().conjugate()).norm();
}

}  // namespace edgeslam
