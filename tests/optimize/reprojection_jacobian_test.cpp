// Analytic Jacobians of the reprojection costs against central differences taken through the SE3
// manifold (tangent of the pose) and directly on the point.
#include <gtest/gtest.h>

#include <random>

#include "optimize/reprojection_costs.h"
#include "optimize/se3_manifold.h"
#include "synthetic_scene.h"

namespace edgeslam {
namespace {

using test::testCamera;

template <int kResiduals>
using Residual = Eigen::Matrix<double, kResiduals, 1>;

template <int kResiduals, typename Cost>
Residual<kResiduals> evaluate(const Cost& cost, const PoseBlock& pose, const double* point) {
  Residual<kResiduals> r;
  const double* params[2] = {pose.data(), point};
  EXPECT_TRUE(cost.Evaluate(params, r.data(), nullptr));
  return r;
}

// Numeric d residual / d delta of the pose tangent, with T <- exp(delta) T.
template <int kResiduals, typename Cost>
Eigen::Matrix<double, kResiduals, 6> numericPoseJacobian(const Cost& cost, const PoseBlock& pose,
                                                         const double* point) {
  const SE3LeftManifold manifold;
  const double h = 1e-6;
  Eigen::Matrix<double, kResiduals, 6> j;
  for (int k = 0; k < 6; ++k) {
    Vector6d delta = Vector6d::Zero();
    PoseBlock plus{}, minus{};
    delta(k) = h;
    manifold.Plus(pose.data(), delta.data(), plus.data());
    delta(k) = -h;
    manifold.Plus(pose.data(), delta.data(), minus.data());
    j.col(k) =
        (evaluate<kResiduals>(cost, plus, point) - evaluate<kResiduals>(cost, minus, point)) /
        (2.0 * h);
  }
  return j;
}

template <int kResiduals>
void checkBundleCost(std::mt19937& rng) {
  const SE3d T_cw = test::perturb(SE3d(), 0.5, 0.4, rng);
  const Eigen::Vector3d point = test::randomVisiblePoint(T_cw, rng);
  const PixelMeasurement m{Eigen::Vector2d(300.0, 200.0), 280.0, 1.0 / 1.2};
  const BundleReprojectionCost<kResiduals> cost(testCamera(), m);
  const PoseBlock pose = toPoseBlock(T_cw);

  Residual<kResiduals> r;
  Eigen::Matrix<double, kResiduals, kPoseBlockSize, Eigen::RowMajor> j_pose;
  Eigen::Matrix<double, kResiduals, 3, Eigen::RowMajor> j_point;
  const double* params[2] = {pose.data(), point.data()};
  double* jacobians[2] = {j_pose.data(), j_point.data()};
  ASSERT_TRUE(cost.Evaluate(params, r.data(), jacobians));

  const Eigen::Matrix<double, kResiduals, 6> numeric_pose =
      numericPoseJacobian<kResiduals>(cost, pose, point.data());
  EXPECT_LT((j_pose.template leftCols<6>() - numeric_pose).norm(), 1e-5 * numeric_pose.norm())
      << "analytic\n"
      << j_pose << "\nnumeric\n"
      << numeric_pose;
  EXPECT_EQ(j_pose.col(6).norm(), 0.0);

  Eigen::Matrix<double, kResiduals, 3> numeric_point;
  for (int k = 0; k < 3; ++k) {
    Eigen::Vector3d plus = point, minus = point;
    plus(k) += 1e-6;
    minus(k) -= 1e-6;
    numeric_point.col(k) = (evaluate<kResiduals>(cost, pose, plus.data()) -
                            evaluate<kResiduals>(cost, pose, minus.data())) /
                           2e-6;
  }
  EXPECT_LT((j_point - numeric_point).norm(), 1e-5 * numeric_point.norm());
}

TEST(ReprojectionJacobian, BundleMonoMatchesNumeric) {
  std::mt19937 rng(1);
  for (int i = 0; i < 20; ++i) checkBundleCost<kMonoResiduals>(rng);
}

TEST(ReprojectionJacobian, BundleStereoMatchesNumeric) {
  std::mt19937 rng(2);
  for (int i = 0; i < 20; ++i) checkBundleCost<kStereoResiduals>(rng);
}

template <int kResiduals>
void checkPoseOnlyCost(std::mt19937& rng) {
  const SE3d T_cw = test::perturb(SE3d(), 0.5, 0.4, rng);
  const Eigen::Vector3d point = test::randomVisiblePoint(T_cw, rng);
  const PixelMeasurement m{Eigen::Vector2d(100.0, 400.0), 90.0, 0.5};
  const PoseReprojectionCost<kResiduals> cost(testCamera(), point, m);
  const PoseBlock pose = toPoseBlock(T_cw);
  Residual<kResiduals> r;
  Eigen::Matrix<double, kResiduals, kPoseBlockSize, Eigen::RowMajor> j;
  const double* params[1] = {pose.data()};
  double* jacobians[1] = {j.data()};
  ASSERT_TRUE(cost.Evaluate(params, r.data(), jacobians));
  const Eigen::Matrix<double, kResiduals, 6> numeric =
      numericPoseJacobian<kResiduals>(cost, pose, nullptr);
  EXPECT_LT((j.template leftCols<6>() - numeric).norm(), 1e-5 * numeric.norm());
}

TEST(ReprojectionJacobian, PoseOnlyMatchesNumeric) {
  std::mt19937 rng(3);
  for (int i = 0; i < 20; ++i) {
    checkPoseOnlyCost<kMonoResiduals>(rng);
    checkPoseOnlyCost<kStereoResiduals>(rng);
  }
}

TEST(ReprojectionJacobian, PointBehindCameraIsRejected) {
  const BundleReprojectionCost<kMonoResiduals> cost(testCamera(), PixelMeasurement{});
  const PoseBlock pose = toPoseBlock(SE3d());
  const Eigen::Vector3d behind(0.0, 0.0, -1.0);
  const double* params[2] = {pose.data(), behind.data()};
  double r[2];
  EXPECT_FALSE(cost.Evaluate(params, r, nullptr));
}

TEST(SE3LeftManifold, PlusMinusRoundTrip) {
  std::mt19937 rng(4);
  const SE3LeftManifold manifold;
  for (int i = 0; i < 20; ++i) {
    const PoseBlock x = toPoseBlock(test::perturb(SE3d(), 1.0, 1.0, rng));
    Vector6d delta;
    delta << 0.1, -0.2, 0.05, 0.3, -0.1, 0.2;
    PoseBlock y{};
    ASSERT_TRUE(manifold.Plus(x.data(), delta.data(), y.data()));
    Vector6d back;
    ASSERT_TRUE(manifold.Minus(y.data(), x.data(), back.data()));
    EXPECT_LT((back - delta).norm(), 1e-12);
    const SE3d expected = SE3d::exp(delta) * fromPoseBlock(x);
    EXPECT_LT((fromPoseBlock(y).matrix() - expected.matrix()).norm(), 1e-12);
  }
}

}  // namespace
}  // namespace edgeslam
