#include "geometry/se3.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

namespace edgeslam {
namespace {

Vector6d tangent(double a, double b, double c, double d, double e, double f) {
  Vector6d xi;
  xi << a, b, c, d, e, f;
  return xi;
}

TEST(SE3, ExpLogRoundTrip) {
  for (const Vector6d& xi : {tangent(0.1, -0.2, 0.3, 0.4, -0.5, 0.6), tangent(1, 2, 3, 0, 0, 0),
                             tangent(0.5, 0, 0, 1e-12, 0, 0), tangent(0, 0, 1, 0, 3.0, 0)}) {
    const Vector6d back = SE3d::exp(xi).log();
    EXPECT_LT((back - xi).norm(), 1e-9) << xi.transpose();
  }
}

TEST(SE3, KnownRotationAboutZ) {
  // 90 degrees about z with zero rho: rotation only.
  const SE3d t = SE3d::exp(tangent(0, 0, 0, 0, 0, std::numbers::pi / 2));
  const Eigen::Vector3d p = t * Eigen::Vector3d(1, 0, 0);
  EXPECT_NEAR(p.x(), 0.0, 1e-12);
  EXPECT_NEAR(p.y(), 1.0, 1e-12);
}

TEST(SE3, ComposeAndInverse) {
  const SE3d a = SE3d::exp(tangent(0.3, -0.1, 2.0, 0.2, 0.1, -0.4));
  const SE3d b = SE3d::exp(tangent(-1.0, 0.5, 0.2, -0.3, 0.7, 0.1));
  const Eigen::Vector3d p(0.4, -2.0, 5.0);
  EXPECT_LT(((a * b) * p - a * (b * p)).norm(), 1e-12);
  EXPECT_LT(((a * a.inverse()).log()).norm(), 1e-12);
  EXPECT_LT((a.matrix() * b.matrix() - (a * b).matrix()).norm(), 1e-12);
}

TEST(SE3, FromMatrixReorthonormalises) {
  Eigen::Matrix4d m = SE3d::exp(tangent(1, 2, 3, 0.1, 0.2, 0.3)).matrix();
  m(0, 0) += 1e-6;  // as printed to a few digits in a dataset file
  const SE3d t = SE3d::fromMatrix(m);
  EXPECT_NEAR(t.rotationMatrix().determinant(), 1.0, 1e-12);
  EXPECT_LT((t.matrix() - m).norm(), 1e-5);
}

TEST(SE3, RotationDistance) {
  const SE3d a = SE3d::exp(tangent(0, 0, 0, 0.2, 0, 0));
  EXPECT_NEAR(rotationDistance(a, SE3d()), 0.2, 1e-12);
}

}  // namespace
}  // namespace edgeslam
