#include "geometry/two_view_initializer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <stdexcept>

#include "geometry/synthetic_scene.h"

namespace edgeslam {
namespace {

using test::angleDeg;
using test::makePose;
using test::makeTwoViewScene;
using test::radToDeg;
using test::SceneOptions;
using test::TwoViewScene;

struct Accuracy {
  double rotation_deg;
  double translation_deg;
  double median_point_error;  // relative to the true depth, after fixing the scale from |t|
  int wrongly_triangulated_outliers;
};

Accuracy accuracyOf(const TwoViewResult& r, const TwoViewScene& s) {
  Accuracy a{};
  a.rotation_deg = radToDeg(rotationDistance(r.current_from_reference, s.cur_from_ref));
  a.translation_deg =
      angleDeg(r.current_from_reference.translation(), s.cur_from_ref.translation());
  const double scale = s.cur_from_ref.translation().norm();
  std::vector<double> errors;
  for (size_t i = 0; i < s.points_ref.size(); ++i) {
    if (!r.triangulated[i]) continue;
    if (s.outlier[i]) {
      ++a.wrongly_triangulated_outliers;
      continue;
    }
    errors.push_back((scale * r.points_reference[i] - s.points_ref[i]).norm() /
                     s.points_ref[i].z());
  }
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  a.median_point_error = errors.empty() ? 1e9 : errors[errors.size() / 2];
  return a;
}

struct MotionCase {
  const char* name;
  SE3d cur_from_ref;
};

class TwoViewGeneralScene : public ::testing::TestWithParam<MotionCase> {};

TEST_P(TwoViewGeneralScene, ChoosesFundamentalAndRecoversMotion) {
  const TwoViewScene s = makeTwoViewScene(GetParam().cur_from_ref, SceneOptions{});
  const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
  ASSERT_TRUE(r.success) << r.reason;
  EXPECT_EQ(r.model, TwoViewModel::kFundamental) << "R_H = " << r.homography_ratio;
  EXPECT_LT(r.homography_ratio, 0.45);
  EXPECT_EQ(r.failure, TwoViewFailure::kNone);
  EXPECT_TRUE(r.reason.empty());
  EXPECT_NEAR(r.current_from_reference.translation().norm(), 1.0, 1e-9);
  const Accuracy a = accuracyOf(r, s);
  EXPECT_LT(a.rotation_deg, 0.5);
  EXPECT_LT(a.translation_deg, 2.0);
  EXPECT_LT(a.median_point_error, 0.05);
  EXPECT_LE(a.wrongly_triangulated_outliers, 3);
  EXPECT_GT(r.num_triangulated, 0.8 * 225);  // 300 matches, 25 % outliers
  EXPECT_GE(r.median_parallax_deg, 1.0);
  EXPECT_LT(r.second_best_good, 0.7 * r.best_good);
}

INSTANTIATE_TEST_SUITE_P(
    Motions, TwoViewGeneralScene,
    ::testing::Values(MotionCase{"sideways", makePose({0.1, 1.0, 0.2}, 8.0, {0.4, 0.05, 0.1})},
                      MotionCase{"forward", makePose({1.0, 0.2, 0.0}, 5.0, {0.1, -0.1, 0.5})},
                      MotionCase{"diagonal", makePose({0.3, -0.4, 1.0}, 12.0, {-0.3, 0.3, -0.2})}),
    [](const auto& param_info) { return std::string(param_info.param.name); });

// A ground-like plane seen obliquely, with enough motion for cheirality to rule out the second
// physically valid homography decomposition (the planar two-fold ambiguity).
SceneOptions groundPlane(double noise_px) {
  SceneOptions o;
  o.planar = true;
  o.plane_normal = Eigen::Vector3d(0.0, -0.8, -0.6);
  o.plane_distance = -3.0;
  o.noise_px = noise_px;
  return o;
}
const SE3d kGroundPlaneMotion = makePose({0.2, 1.0, 0.0}, -20.0, {1.2, 0.2, 0.4});

TEST(TwoViewInitializer, PlanarSceneChoosesHomographyAndRecoversMotion) {
  const TwoViewScene s = makeTwoViewScene(kGroundPlaneMotion, groundPlane(0.5));
  const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
  ASSERT_TRUE(r.success) << r.reason;
  EXPECT_EQ(r.model, TwoViewModel::kHomography) << "R_H = " << r.homography_ratio;
  EXPECT_GT(r.homography_ratio, 0.45);
  EXPECT_FALSE(r.used_fallback);
  const Accuracy a = accuracyOf(r, s);
  EXPECT_LT(a.rotation_deg, 0.5);
  EXPECT_LT(a.translation_deg, 2.0);
  EXPECT_LT(a.median_point_error, 0.05);
  EXPECT_LE(a.wrongly_triangulated_outliers, 3);
}

TEST(TwoViewInitializer, PlanarSceneWithNoiseAtSigmaStillReconstructsTheHomography) {
  // At noise ~ sigma the score ratio of a plane sits near 0.45 and may pick F; either way the
  // result must be the homography's reconstruction.
  const TwoViewScene s = makeTwoViewScene(kGroundPlaneMotion, groundPlane(1.0));
  const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
  ASSERT_TRUE(r.success) << r.reason;
  EXPECT_EQ(r.model, TwoViewModel::kHomography);
  EXPECT_EQ(r.used_fallback, r.homography_ratio <= 0.45);
  const Accuracy a = accuracyOf(r, s);
  EXPECT_LT(a.rotation_deg, 0.5);
  EXPECT_LT(a.translation_deg, 2.0);
}

TEST(TwoViewInitializer, RefusesThePlanarTwoFoldAmbiguity) {
  // Nearly fronto-parallel plane, sideways motion: both decompositions put most points in front.
  SceneOptions o;
  o.planar = true;
  o.noise_px = 0.5;
  const TwoViewScene s = makeTwoViewScene(makePose({0.1, 1.0, 0.2}, 8.0, {0.5, 0.05, 0.1}), o);
  const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.model, TwoViewModel::kHomography);
  EXPECT_EQ(r.failure, TwoViewFailure::kAmbiguousMotion) << r.reason;
  EXPECT_GT(r.second_best_good, 0.7 * r.best_good);
}

TEST(TwoViewInitializer, RefusesPureRotation) {
  const TwoViewScene s =
      makeTwoViewScene(makePose({0.2, 1.0, 0.1}, 10.0, Eigen::Vector3d::Zero()), SceneOptions{});
  const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.failure, TwoViewFailure::kLowParallax) << r.reason;
  EXPECT_NE(r.reason.find("parallax"), std::string::npos) << r.reason;
  EXPECT_LT(r.median_parallax_deg, 0.5);
  EXPECT_EQ(std::count(r.triangulated.begin(), r.triangulated.end(), 1), 0);
}

TEST(TwoViewInitializer, RefusesTooLittleTranslation) {
  // 2 cm sideways at 2-6 m: a few tenths of a degree of parallax.
  const TwoViewScene s =
      makeTwoViewScene(makePose({0.0, 1.0, 0.0}, 3.0, {0.02, 0.0, 0.0}), SceneOptions{});
  const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.failure, TwoViewFailure::kLowParallax) << r.reason;
}

TEST(TwoViewInitializer, ParallaxThresholdIsConfigurable) {
  const TwoViewScene s =
      makeTwoViewScene(makePose({0.1, 1.0, 0.2}, 8.0, {0.4, 0.05, 0.1}), SceneOptions{});
  TwoViewOptions strict;
  strict.min_parallax_deg = 30.0;
  const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K, strict);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.failure, TwoViewFailure::kLowParallax);
  TwoViewOptions many;
  many.min_triangulated = 1000;
  const TwoViewResult q = initializeTwoView(s.ref_px, s.cur_px, s.K, many);
  EXPECT_FALSE(q.success);
  EXPECT_EQ(q.failure, TwoViewFailure::kTooFewTriangulated) << q.reason;
}

TEST(TwoViewInitializer, TooFewMatchesAndBadInput) {
  const TwoViewScene s =
      makeTwoViewScene(makePose({0.1, 1.0, 0.2}, 8.0, {0.4, 0.05, 0.1}), SceneOptions{});
  const std::vector<Eigen::Vector2d> ref(s.ref_px.begin(), s.ref_px.begin() + 20);
  const std::vector<Eigen::Vector2d> cur(s.cur_px.begin(), s.cur_px.begin() + 20);
  const TwoViewResult r = initializeTwoView(ref, cur, s.K);
  EXPECT_FALSE(r.success);
  EXPECT_EQ(r.failure, TwoViewFailure::kTooFewMatches);
  EXPECT_EQ(r.triangulated.size(), 20u);

  EXPECT_THROW(initializeTwoView(s.ref_px, cur, s.K), std::invalid_argument);
  std::vector<Eigen::Vector2d> nan_px = s.cur_px;
  nan_px[7].y() = std::nan("");
  EXPECT_THROW(initializeTwoView(s.ref_px, nan_px, s.K), std::invalid_argument);
  EXPECT_THROW(initializeTwoView(s.ref_px, s.cur_px, Eigen::Matrix3d::Zero()),
               std::invalid_argument);
  TwoViewOptions bad;
  bad.sigma_px = 0.0;
  EXPECT_THROW(initializeTwoView(s.ref_px, s.cur_px, s.K, bad), std::invalid_argument);

  // Every match on the same pixel: no model at all.
  const std::vector<Eigen::Vector2d> same(100, Eigen::Vector2d(10.0, 10.0));
  const TwoViewResult d = initializeTwoView(same, same, s.K);
  EXPECT_FALSE(d.success);
  EXPECT_EQ(d.failure, TwoViewFailure::kNoModel) << d.reason;
}

TEST(TwoViewInitializer, ParallelAndSequentialAgree) {
  const TwoViewScene s =
      makeTwoViewScene(makePose({0.1, 1.0, 0.2}, 8.0, {0.4, 0.05, 0.1}), SceneOptions{});
  TwoViewOptions sequential;
  sequential.parallel = false;
  const TwoViewResult a = initializeTwoView(s.ref_px, s.cur_px, s.K);
  const TwoViewResult b = initializeTwoView(s.ref_px, s.cur_px, s.K, sequential);
  ASSERT_TRUE(a.success && b.success);
  EXPECT_EQ(a.score_homography, b.score_homography);
  EXPECT_EQ(a.score_fundamental, b.score_fundamental);
  EXPECT_EQ(a.triangulated, b.triangulated);
}

TEST(TwoViewInitializer, NormalizesToUnitMedianDepth) {
  const TwoViewScene s =
      makeTwoViewScene(makePose({0.1, 1.0, 0.2}, 8.0, {0.4, 0.05, 0.1}), SceneOptions{});
  TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
  ASSERT_TRUE(r.success) << r.reason;
  const Eigen::Vector3d t_before = r.current_from_reference.translation();
  const double factor = normalizeToUnitMedianDepth(r);
  ASSERT_GT(factor, 0.0);
  std::vector<double> depths;
  for (size_t i = 0; i < r.triangulated.size(); ++i) {
    if (r.triangulated[i]) depths.push_back(r.points_reference[i].z());
  }
  std::nth_element(depths.begin(), depths.begin() + depths.size() / 2, depths.end());
  EXPECT_NEAR(depths[depths.size() / 2], 1.0, 1e-12);
  EXPECT_LT((r.current_from_reference.translation() - factor * t_before).norm(), 1e-12);
  // True median depth is about 4 m for a 0.41 m baseline: the normalised baseline is ~0.1.
  EXPECT_NEAR(r.current_from_reference.translation().norm(), 0.41 / 4.0, 0.03);

  TwoViewResult empty;
  EXPECT_EQ(normalizeToUnitMedianDepth(empty), 0.0);
}

TEST(TwoViewInitializer, ThousandMatchesSucceedAndReportTime) {
  SceneOptions o;
  o.num_points = 1000;
  const TwoViewScene s = makeTwoViewScene(makePose({0.1, 1.0, 0.2}, 8.0, {0.4, 0.05, 0.1}), o);
  initializeTwoView(s.ref_px, s.cur_px, s.K);  // warm-up (thread start, allocations)
  constexpr int kRuns = 5;
  double best_wall_ms = 1e9;
  const std::clock_t cpu_start = std::clock();
  for (int k = 0; k < kRuns; ++k) {
    const auto start = std::chrono::steady_clock::now();
    const TwoViewResult r = initializeTwoView(s.ref_px, s.cur_px, s.K);
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    ASSERT_TRUE(r.success) << r.reason;
    best_wall_ms = std::min(best_wall_ms, ms);
  }
  // Process CPU time (both threads) is robust to a loaded machine; wall time is what a caller
  // waits for.
  const double cpu_ms =
      1000.0 * static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC / kRuns;
  std::printf(
      "[ timing ] two-view initialisation, 1000 matches: %.1f ms wall (best of %d), %.1f ms CPU "
      "(mean)\n",
      best_wall_ms, kRuns, cpu_ms);
  // Speed is tracked by the benchmarks, not asserted here (shared, noisy machines).
}

}  // namespace
}  // namespace edgeslam
