#include "geometry/pnp.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "geometry/synthetic_scene.h"

namespace edgeslam {
namespace {

using test::makePose;
using test::radToDeg;
using test::syntheticK;

struct PnpScene {
  SE3d cam_from_world;
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  std::vector<char> outlier;
};

PnpScene makePnpScene(int n, double noise_px, double outlier_fraction, unsigned seed) {
  PnpScene s;
  s.cam_from_world = makePose({0.3, 1.0, -0.2}, 40.0, {0.8, -0.5, 2.0});
  const Eigen::Matrix3d K = syntheticK();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(0.0, test::kImageWidth), uy(0.0, test::kImageHeight),
      depth(1.5, 8.0);
  std::normal_distribution<double> noise(0.0, noise_px);
  const SE3d world_from_cam = s.cam_from_world.inverse();
  for (int i = 0; i < n; ++i) {
    const Eigen::Vector2d px(ux(rng), uy(rng));
    const Eigen::Vector3d Xc = (K.inverse() * px.homogeneous()) * depth(rng);
    s.points.push_back(world_from_cam * Xc);
    s.pixels.push_back(px + Eigen::Vector2d(noise(rng), noise(rng)));
    s.outlier.push_back(0);
  }
  const int outliers = static_cast<int>(outlier_fraction * n);
  for (int i = 0; i < outliers; ++i) {
    const int k = i * n / outliers;
    Eigen::Vector2d wrong;
    do {
      wrong = {ux(rng), uy(rng)};
    } while ((wrong - s.pixels[k]).norm() < 20.0);
    s.pixels[k] = wrong;
    s.outlier[k] = 1;
  }
  return s;
}

TEST(Pnp, RecoversPoseWithThirtyPercentOutliers) {
  for (unsigned seed : {1u, 2u, 3u}) {
    const PnpScene s = makePnpScene(200, 0.7, 0.3, seed);
    const PnpResult r = solvePnpRansac(s.pixels, s.points, syntheticK());
    ASSERT_TRUE(r.success) << r.reason;
    EXPECT_TRUE(r.reason.empty());
    const SE3d& est = r.camera_from_world;
    const double position_error =
        (est.inverse().translation() - s.cam_from_world.inverse().translation()).norm();
    EXPECT_LT(position_error, 0.01) << "seed " << seed;
    EXPECT_LT(radToDeg(rotationDistance(est, s.cam_from_world)), 0.2) << "seed " << seed;
    int missed = 0, accepted_outliers = 0;
    for (size_t i = 0; i < s.outlier.size(); ++i) {
      if (!s.outlier[i] && !r.inliers[i]) ++missed;
      if (s.outlier[i] && r.inliers[i]) ++accepted_outliers;
    }
    EXPECT_LE(missed, 3);
    EXPECT_EQ(accepted_outliers, 0);
    EXPECT_EQ(r.num_inliers, static_cast<int>(std::count(r.inliers.begin(), r.inliers.end(), 1)));
    EXPECT_LT(r.rmse_px, 1.5);
  }
}

TEST(Pnp, ReportsDegenerateInput) {
  const Eigen::Matrix3d K = syntheticK();
  const PnpScene s = makePnpScene(50, 0.5, 0.0, 4);
  const std::vector<Eigen::Vector2d> few_px(s.pixels.begin(), s.pixels.begin() + 5);
  const std::vector<Eigen::Vector3d> few_pts(s.points.begin(), s.points.begin() + 5);
  PnpResult r = solvePnpRansac(few_px, few_pts, K);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.reason.find("correspondences"), std::string::npos) << r.reason;

  const std::vector<Eigen::Vector3d> same(50, Eigen::Vector3d(1.0, 2.0, 3.0));
  r = solvePnpRansac(s.pixels, same, K);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.reason.find("coincide"), std::string::npos) << r.reason;

  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 50; ++i) line.emplace_back(0.1 * i, 0.2 * i, 3.0 + 0.05 * i);
  r = solvePnpRansac(s.pixels, line, K);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.reason.find("collinear"), std::string::npos) << r.reason;

  const std::vector<Eigen::Vector2d> one_pixel(50, Eigen::Vector2d(100.0, 100.0));
  r = solvePnpRansac(one_pixel, s.points, K);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.reason.find("pixels"), std::string::npos) << r.reason;

  // Pure noise: no pose explains enough correspondences.
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(0.0, 400.0);
  std::vector<Eigen::Vector2d> random_px;
  for (int i = 0; i < 50; ++i) random_px.emplace_back(u(rng), u(rng));
  PnpOptions strict;
  strict.min_inliers = 20;
  r = solvePnpRansac(random_px, s.points, K, strict);
  EXPECT_FALSE(r.success);
  EXPECT_FALSE(r.reason.empty());
}

TEST(Pnp, RejectsInvalidInput) {
  const PnpScene s = makePnpScene(20, 0.5, 0.0, 5);
  const std::vector<Eigen::Vector3d> fewer(s.points.begin(), s.points.begin() + 10);
  EXPECT_THROW(solvePnpRansac(s.pixels, fewer, syntheticK()), std::invalid_argument);
  std::vector<Eigen::Vector3d> nan_points = s.points;
  nan_points[3].z() = std::nan("");
  EXPECT_THROW(solvePnpRansac(s.pixels, nan_points, syntheticK()), std::invalid_argument);
  EXPECT_THROW(solvePnpRansac(s.pixels, s.points, Eigen::Matrix3d::Identity() * -1.0),
               std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
