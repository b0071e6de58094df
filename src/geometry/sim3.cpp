#include "geometry/sim3.h"

#include <cmath>
#include <stdexcept>

#include "geometry/so3.h"

namespace edgeslam {
namespace {

// W = integral_0^1 e^(sigma tau) R(tau omega) dtau, the map from rho to the group translation.
Eigen::Matrix3d sim3TranslationJacobian(const Eigen::Vector3d& omega, double sigma) {
  const double theta = omega.norm();
  const Eigen::Matrix3d w = skew(omega);
  const Eigen::Matrix3d identity = Eigen::Matrix3d::Identity();
  const bool tiny_sigma = std::abs(sigma) < 1e-10;
  const double es = std::exp(sigma);
  const double c0 = tiny_sigma ? 1.0 : std::expm1(sigma) / sigma;
  double c1 = 0.0;  // coefficient of [omega]x
  double c2 = 0.0;  // coefficient of [omega]x^2
  if (theta < 1e-8) {
    // Limits of the coefficients as theta -> 0: integrals of tau e^(sigma tau) and tau^2/2 e^(sigma
    // tau).
    if (tiny_sigma) {
      c1 = 0.5;
      c2 = 1.0 / 6.0;
    } else {
      const double s2 = sigma * sigma;
      c1 = (es * (sigma - 1.0) + 1.0) / s2;
      c2 = (es * (s2 - 2.0 * sigma + 2.0) - 2.0) / (2.0 * s2 * sigma);
    }
  } else {
    const double a = es * std::sin(theta);
    const double b = es * std::cos(theta);
    const double c = theta * theta + sigma * sigma;
    const double p = (a * sigma + (1.0 - b) * theta) / c;  // integral of e^(st) sin(theta t)
    const double q = (b * sigma + a * theta - sigma) / c;  // integral of e^(st) cos(theta t)
    c1 = p / theta;
    c2 = (c0 - q) / (theta * theta);
  }
  return c0 * identity + c1 * w + c2 * w * w;
}

}  // namespace

Sim3d::Sim3d(double scale, const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
    : scale_(scale), rotation_(rotation.normalized()), translation_(translation) {
  if (!(scale > 0.0) || !std::isfinite(scale)) {
    throw std::invalid_argument("Sim3d: scale must be positive and finite");
  }
}

Sim3d Sim3d::exp(const Vector7d& xi) {
  const Eigen::Vector3d rho = xi.head<3>();
  const Eigen::Vector3d omega = xi.segment<3>(3);
  const double sigma = xi(6);
  return {std::exp(sigma), so3Exp(omega), sim3TranslationJacobian(omega, sigma) * rho};
}

Vector7d Sim3d::log() const {
  const Eigen::Vector3d omega = so3Log(rotation_);
  const double sigma = std::log(scale_);
  Vector7d xi;
  xi.head<3>() = sim3TranslationJacobian(omega, sigma).inverse() * translation_;
  xi.segment<3>(3) = omega;
  xi(6) = sigma;
  return xi;
}

Sim3d Sim3d::inverse() const {
  const Eigen::Quaterniond r_inv = rotation_.conjugate();
  const double s_inv = 1.0 / scale_;
  return {s_inv, r_inv, -s_inv * (r_inv * translation_)};
}

Eigen::Matrix4d Sim3d::matrix() const {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = scale_ * rotation_.toRotationMatrix();
  m.topRightCorner<3, 1>() = translation_;
  return m;
}

}  // namespace edgeslam
