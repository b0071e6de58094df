#include "optimize/sim3_optimizer.h"

#include <gtest/gtest.h>

#include <random>

#include "geometry/so3.h"
#include "synthetic_scene.h"

namespace edgeslam {
namespace {

using test::testCamera;

// Matches between two keyframes related by S_12 (point1 = S_12 * point2), exact projections.
std::vector<Sim3Match> makeMatches(const Sim3d& S_12, int count, std::mt19937& rng) {
  const CameraProjection cam = testCamera();
  std::vector<Sim3Match> matches;
  while (static_cast<int>(matches.size()) < count) {
    Sim3Match m;
    m.point1 = test::randomVisiblePoint(SE3d(), rng, 2.0, 8.0);
    m.point2 = S_12.inverse() * m.point1;
    if (m.point2.z() < 0.5) continue;
    m.pixel1 = cam.project(m.point1);
    m.pixel2 = cam.project(m.point2);
    m.sigma1_px = m.sigma2_px = 1.0;
    matches.push_back(m);
  }
  return matches;
}

Sim3d perturbSim3(const Sim3d& s, double scale_factor, double angle_rad, double distance) {
  return Sim3d(s.scale() * scale_factor,
               Eigen::Quaterniond(so3Exp(Eigen::Vector3d(angle_rad, -angle_rad, 0.5 * angle_rad))) *
                   s.rotation(),
               s.translation() + Eigen::Vector3d(distance, -distance, distance));
}

const Sim3d kTrueS12(1.3, Eigen::Quaterniond(so3Exp(Eigen::Vector3d(0.05, 0.15, -0.03))),
                     Eigen::Vector3d(0.3, -0.1, 0.2));

TEST(Sim3Optimizer, RecoversAKnownSimilarityWithScale) {
  std::mt19937 rng(40);
  const std::vector<Sim3Match> matches = makeMatches(kTrueS12, 80, rng);
  const Sim3d start = perturbSim3(kTrueS12, 1.08, test::degToRad(2.0), 0.05);
  const Sim3RefinementResult r = refineSim3(start, matches, testCamera(), testCamera());
  ASSERT_TRUE(r.success);
  EXPECT_EQ(r.inliers, 80);
  EXPECT_NEAR(r.S_12.scale(), 1.3, 1e-6);
  EXPECT_LT(so3Log(r.S_12.rotation() * kTrueS12.rotation().conjugate()).norm(), 1e-7);
  EXPECT_LT((r.S_12.translation() - kTrueS12.translation()).norm(), 1e-6);
}

TEST(Sim3Optimizer, FlagsOutlierMatches) {
  std::mt19937 rng(41);
  std::vector<Sim3Match> matches = makeMatches(kTrueS12, 100, rng);
  std::vector<bool> injected(matches.size(), false);
  for (std::size_t i = 0; i < matches.size(); i += 5) {
    matches[i].pixel2 += Eigen::Vector2d(40.0, -35.0);  // a wrong match seen in image 2
    injected[i] = true;
  }
  const Sim3d start = perturbSim3(kTrueS12, 0.95, test::degToRad(1.0), 0.03);
  const Sim3RefinementResult r = refineSim3(start, matches, testCamera(), testCamera());
  ASSERT_TRUE(r.success);
  EXPECT_EQ(r.outliers, injected);
  EXPECT_EQ(r.inliers, 80);
  EXPECT_NEAR(r.S_12.scale(), 1.3, 1e-6);
}

TEST(Sim3Optimizer, FixedScaleRefinesARigidTransform) {
  std::mt19937 rng(42);
  const Sim3d truth(1.0, kTrueS12.rotation(), kTrueS12.translation());
  const std::vector<Sim3Match> matches = makeMatches(truth, 60, rng);
  Sim3RefinementOptions options;
  options.fix_scale = true;
  const Sim3RefinementResult r = refineSim3(perturbSim3(truth, 1.0, test::degToRad(2.0), 0.05),
                                            matches, testCamera(), testCamera(), options);
  ASSERT_TRUE(r.success);
  EXPECT_DOUBLE_EQ(r.S_12.scale(), 1.0);
  EXPECT_LT((r.S_12.translation() - truth.translation()).norm(), 1e-6);
}

TEST(Sim3Optimizer, FailsWithTooFewInliers) {
  std::mt19937 rng(43);
  std::vector<Sim3Match> matches = makeMatches(kTrueS12, 12, rng);
  for (std::size_t i = 0; i < 6; ++i) matches[i].pixel1 += Eigen::Vector2d(50.0, 50.0);
  const Sim3RefinementResult r = refineSim3(kTrueS12, matches, testCamera(), testCamera());
  EXPECT_FALSE(r.success);
}

// Two monocular maps of one place seen from one spot (two clients on the same frames): camera 2
// stands where camera 1 stands, map 2 is at 1/1.3 of map 1's scale, and each map's points sit a
// few percent off along their rays (depth error; the pixels are exact). Reprojection is blind
// to a scale about the shared centre.
std::vector<Sim3Match> makeCoincidentViews(const Sim3d& S_12, int count, std::mt19937& rng) {
  const CameraProjection cam = testCamera();
  std::normal_distribution<double> depth_error(0.0, 0.04);
  std::vector<Sim3Match> matches;
  while (static_cast<int>(matches.size()) < count) {
    const Eigen::Vector3d truth1 = test::randomVisiblePoint(SE3d(), rng, 3.0, 30.0);
    const Eigen::Vector3d truth2 = S_12.inverse() * truth1;
    Sim3Match m;
    m.point1 = truth1 * (1.0 + depth_error(rng));
    m.point2 = truth2 * (1.0 + depth_error(rng));
    m.pixel1 = cam.project(truth1);
    m.pixel2 = cam.project(truth2);
    matches.push_back(m);
  }
  return matches;
}

TEST(Sim3Optimizer, TwoMapsSeenFromOneSpotTakeTheScaleFromThePointsRanges) {
  std::mt19937 rng(43);
  const Sim3d truth(1.3, Eigen::Quaterniond(so3Exp(Eigen::Vector3d(0.02, -0.04, 0.01))),
                    Eigen::Vector3d::Zero());
  const std::vector<Sim3Match> matches = makeCoincidentViews(truth, 150, rng);
  // A RANSAC estimate whose scale came out of a few noisy points.
  const Sim3d start(1.0, truth.rotation(), Eigen::Vector3d(0.01, 0.0, -0.02));

  Sim3RefinementOptions options;
  options.scale_from_ranges_below_baseline = 0.02;
  const Sim3RefinementResult held = refineSim3(start, matches, testCamera(), testCamera(), options);
  ASSERT_TRUE(held.success);
  EXPECT_TRUE(held.scale_from_ranges);
  EXPECT_NEAR(held.S_12.scale(), 1.3, 0.03);
  EXPECT_LT(test::radToDeg(so3Log(held.S_12.rotation() * truth.rotation().conjugate()).norm()),
            0.1);

  // Reprojection alone leaves the scale wherever it started.
  const Sim3RefinementResult free = refineSim3(start, matches, testCamera(), testCamera());
  ASSERT_TRUE(free.success);
  EXPECT_FALSE(free.scale_from_ranges);
  EXPECT_GT(std::abs(free.S_12.scale() - 1.3), 0.1);
}

TEST(Sim3Optimizer, ViewsApartKeepTheScaleReprojectionSees) {
  std::mt19937 rng(44);
  const std::vector<Sim3Match> matches = makeMatches(kTrueS12, 80, rng);
  Sim3RefinementOptions options;
  options.scale_from_ranges_below_baseline = 0.02;
  const Sim3d start = perturbSim3(kTrueS12, 1.08, test::degToRad(2.0), 0.05);
  const Sim3RefinementResult r = refineSim3(start, matches, testCamera(), testCamera(), options);
  ASSERT_TRUE(r.success);
  EXPECT_FALSE(r.scale_from_ranges);
  EXPECT_NEAR(r.S_12.scale(), 1.3, 1e-6);
}

TEST(Sim3Optimizer, RejectsBadInput) {
  std::mt19937 rng(44);
  std::vector<Sim3Match> matches = makeMatches(kTrueS12, 12, rng);
  matches[3].sigma2_px = 0.0;
  EXPECT_THROW(refineSim3(kTrueS12, matches, testCamera(), testCamera()), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
