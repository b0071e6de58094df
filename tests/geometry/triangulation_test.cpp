#include "geometry/triangulation.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>
#include <vector>

#include "geometry/synthetic_scene.h"

namespace edgeslam {
namespace {

using test::makePose;

Eigen::Vector2d normalizedProjection(const SE3d& cam_from_world, const Eigen::Vector3d& X) {
  return (cam_from_world * X).hnormalized();
}

TEST(Triangulation, TwoViewDltIsExactWithoutNoise) {
  const SE3d cam1 = makePose({0.2, 1.0, 0.1}, 15.0, {0.3, -0.1, 0.5});
  const SE3d cam2 = makePose({-0.5, 0.3, 1.0}, 25.0, {-0.4, 0.2, 0.3});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0.0;
  for (int k = 0; k < 100; ++k) {
    // Points in front of both cameras: placed along cam1's optical axis region.
    const Eigen::Vector3d X = cam1.inverse() * Eigen::Vector3d(u(rng), u(rng), 3.0 + u(rng));
    ASSERT_TRUE(isInFrontOfBoth(cam1, cam2, X));
    const auto Y =
        triangulateDlt(cam1, normalizedProjection(cam1, X), cam2, normalizedProjection(cam2, X));
    ASSERT_TRUE(Y.has_value());
    worst = std::max(worst, (*Y - X).norm());
  }
  EXPECT_LT(worst, 1e-9);
}

TEST(Triangulation, MultiViewDltIsExactWithoutNoiseAndAveragesNoise) {
  const Eigen::Vector3d X(0.4, -0.3, 5.0);
  std::vector<SE3d> poses;
  std::vector<Eigen::Vector2d> exact, noisy;
  std::mt19937 rng(5);
  std::normal_distribution<double> noise(0.0, 1.0 / 500.0);  // ~1 px at f = 500
  for (int v = 0; v < 6; ++v) {
    poses.push_back(makePose({0.0, 1.0, 0.0}, 2.0 * v, {-0.2 * v, 0.05 * v, 0.0}));
    exact.push_back(normalizedProjection(poses.back(), X));
    noisy.push_back(exact.back() + Eigen::Vector2d(noise(rng), noise(rng)));
  }
  const auto Y = triangulateDlt(poses, exact);
  ASSERT_TRUE(Y.has_value());
  EXPECT_LT((*Y - X).norm(), 1e-9);
  const auto Z = triangulateDlt(poses, noisy);
  ASSERT_TRUE(Z.has_value());
  EXPECT_LT((*Z - X).norm(), 0.1);  // 1 m baseline at 5 m depth, 1 px noise
  EXPECT_GT((*Z - X).norm(), 0.0);
}

TEST(Triangulation, MultiViewRejectsMismatchedInput) {
  const std::vector<SE3d> poses(3);
  const std::vector<Eigen::Vector2d> two(2, Eigen::Vector2d::Zero());
  EXPECT_THROW(triangulateDlt(poses, two), std::invalid_argument);
  const std::vector<SE3d> one(1);
  const std::vector<Eigen::Vector2d> single(1, Eigen::Vector2d::Zero());
  EXPECT_THROW(triangulateDlt(one, single), std::invalid_argument);
}

TEST(Triangulation, FromPixelsWithTwoCameras) {
  CameraIntrinsics a;
  a.width = 640;
  a.height = 480;
  a.fx = a.fy = 520.0;
  a.cx = 320.0;
  a.cy = 240.0;
  CameraIntrinsics b = a;
  b.fx = 600.0;
  b.cy = 250.0;
  const PinholeCamera cam_a(a), cam_b(b);
  const SE3d pose_a;
  const SE3d pose_b = makePose({0.0, 1.0, 0.0}, -5.0, {-0.5, 0.0, 0.0});
  const Eigen::Vector3d X(0.3, 0.2, 4.0);
  const auto px_a = cam_a.project(pose_a * X);
  const auto px_b = cam_b.project(pose_b * X);
  ASSERT_TRUE(px_a && px_b);
  const auto Y = triangulatePixels(cam_a, pose_a, *px_a, cam_b, pose_b, *px_b);
  ASSERT_TRUE(Y.has_value());
  EXPECT_LT((*Y - X).norm(), 1e-9);
  EXPECT_LT(reprojectionErrorSquared(cam_a, pose_a, *Y, *px_a), 1e-12);
  EXPECT_NEAR(reprojectionErrorSquared(cam_b, pose_b, *Y, *px_b + Eigen::Vector2d(3.0, 4.0)), 25.0,
              1e-6);
  EXPECT_NEAR(reprojectionErrorSquared(cam_b.K(), pose_b, *Y, *px_b + Eigen::Vector2d(0.0, 2.0)),
              4.0, 1e-6);
}

TEST(Triangulation, CheiralityAndReprojectionOfPointsBehind) {
  const SE3d cam;
  const SE3d turned = makePose({0.0, 1.0, 0.0}, 180.0, {0.0, 0.0, 0.0});
  const Eigen::Vector3d ahead(0.1, 0.0, 2.0);
  EXPECT_TRUE(isInFront(cam, ahead));
  EXPECT_FALSE(isInFront(turned, ahead));
  EXPECT_FALSE(isInFrontOfBoth(cam, turned, ahead));
  EXPECT_FALSE(isInFront(cam, ahead, 2.5));  // closer than the minimum depth
  EXPECT_DOUBLE_EQ(depthInCamera(cam, ahead), 2.0);
  EXPECT_TRUE(std::isinf(reprojectionErrorSquared(test::syntheticK(), turned, ahead, {0.0, 0.0})));
}

TEST(Triangulation, ParallaxOfKnownGeometry) {
  // Centres one unit apart, point one unit in front of the first: 45 degrees.
  const Eigen::Vector3d c1(0.0, 0.0, 0.0), c2(1.0, 0.0, 0.0), X(0.0, 0.0, 1.0);
  EXPECT_NEAR(parallaxCosine(c1, c2, X), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(parallaxDegrees(parallaxCosine(c1, c2, X)), 45.0, 1e-9);
  EXPECT_DOUBLE_EQ(parallaxCosine(c1, c1, X), 1.0);
  EXPECT_DOUBLE_EQ(parallaxCosine(c1, c2, c1), 1.0);  // degenerate: point at a centre

  const SE3d pose1;
  const SE3d pose2(Eigen::Matrix3d::Identity(), Eigen::Vector3d(-1.0, 0.0, 0.0));  // centre +x
  EXPECT_LT((cameraCenter(pose2) - c2).norm(), 1e-12);
  EXPECT_NEAR(parallaxCosine(pose1, pose2, X), std::sqrt(0.5), 1e-12);
}

}  // namespace
}  // namespace edgeslam
