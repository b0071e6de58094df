#include "geometry/sim3.h"

#include <gtest/gtest.h>

#include "geometry/so3.h"

namespace edgeslam {
namespace {

Vector7d tangent(double a, double b, double c, double d, double e, double f, double g) {
  Vector7d xi;
  xi << a, b, c, d, e, f, g;
  return xi;
}

// Translation of exp(xi) by direct numerical integration of e^(sigma t) R(t omega) rho dt.
Eigen::Vector3d integratedTranslation(const Vector7d& xi) {
  const int n = 2000;  // Simpson's rule, even count
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int i = 0; i <= n; ++i) {
    const double t = static_cast<double>(i) / n;
    const double w = (i == 0 || i == n) ? 1.0 : (i % 2 == 1 ? 4.0 : 2.0);
    sum += w * std::exp(xi(6) * t) *
           (so3Exp(t * Eigen::Vector3d(xi.segment<3>(3))) * Eigen::Vector3d(xi.head<3>()));
  }
  return sum / (3.0 * n);
}

TEST(Sim3, ExpMatchesNumericalIntegral) {
  for (const Vector7d& xi :
       {tangent(0.1, -0.2, 0.3, 0.4, -0.5, 0.6, 0.7), tangent(1, 2, 3, 0, 0, 0, -0.3),
        tangent(1, 2, 3, 0.3, 0, 0, 0), tangent(1, -1, 2, 1e-10, 0, 0, 1e-12)}) {
    EXPECT_LT((Sim3d::exp(xi).translation() - integratedTranslation(xi)).norm(), 1e-9)
        << xi.transpose();
  }
}

TEST(Sim3, ExpLogRoundTrip) {
  for (const Vector7d& xi :
       {tangent(0.1, -0.2, 0.3, 0.4, -0.5, 0.6, 0.7), tangent(1, 2, 3, 0, 0, 0, -0.3),
        tangent(0, 0, 0, 0, 0, 0, 0), tangent(5, 0, 0, 0, 2.5, 0, 1.5)}) {
    EXPECT_LT((Sim3d::exp(xi).log() - xi).norm(), 1e-9) << xi.transpose();
  }
}

TEST(Sim3, ComposeInverseAndAction) {
  const Sim3d a = Sim3d::exp(tangent(0.3, -0.1, 2.0, 0.2, 0.1, -0.4, 0.5));
  const Sim3d b = Sim3d::exp(tangent(-1.0, 0.5, 0.2, -0.3, 0.7, 0.1, -0.2));
  const Eigen::Vector3d p(0.4, -2.0, 5.0);
  EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-12);
  EXPECT_LT((a.inverse() * (a * p) - p).norm(), 1e-12);
  EXPECT_LT((a.matrix() * b.matrix() - (a * b).matrix()).norm(), 1e-12);
  EXPECT_NEAR((a * b).scale(), a.scale() * b.scale(), 1e-12);
}

TEST(Sim3, ZeroScaleLogMatchesSE3) {
  Vector6d xi6;
  xi6 << 0.3, -0.2, 1.0, 0.5, 0.1, -0.2;
  const SE3d rigid = SE3d::exp(xi6);
  const Vector7d xi7 = Sim3d(rigid).log();
  EXPECT_LT((xi7.head<6>() - xi6).norm(), 1e-9);
  EXPECT_NEAR(xi7(6), 0.0, 1e-15);
}

TEST(Sim3, RejectsNonPositiveScale) {
  EXPECT_THROW(Sim3d(0.0, Eigen::Quaterniond::Identity(), Eigen::Vector3d::Zero()),
               std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
