// Homography, fundamental and essential matrices on synthetic scenes.
#include <gtest/gtest.h>

#include <Eigen/SVD>
#include <stdexcept>

#include "geometry/essential.h"
#include "geometry/fundamental.h"
#include "geometry/homography.h"
#include "geometry/point_normalization.h"
#include "geometry/ransac_sampling.h"
#include "geometry/relative_pose_refinement.h"
#include "geometry/so3.h"
#include "geometry/synthetic_scene.h"

namespace edgeslam {
namespace {

using test::makePose;
using test::makeTwoViewScene;
using test::radToDeg;
using test::SceneOptions;

const SE3d kMotion = makePose({0.1, 1.0, 0.2}, 8.0, {0.4, 0.05, 0.1});

SceneOptions noiseFree(bool planar) {
  SceneOptions o;
  o.planar = planar;
  o.noise_px = 0.0;
  o.outlier_fraction = 0.0;
  o.num_points = 100;
  return o;
}

Eigen::Matrix3d trueFundamental(const SE3d& cur_from_ref, const Eigen::Matrix3d& K) {
  const Eigen::Matrix3d K_inv = K.inverse();
  const Eigen::Matrix3d F =
      K_inv.transpose() * skew(cur_from_ref.translation()) * cur_from_ref.rotationMatrix() * K_inv;
  return F / F.norm();
}

double sameUpToSign(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b) {
  return std::min((a / a.norm() - b / b.norm()).norm(), (a / a.norm() + b / b.norm()).norm());
}

TEST(PointNormalization, CentroidZeroMeanDistanceSqrt2) {
  const std::vector<Eigen::Vector2d> pts = {{10, 20}, {30, 20}, {10, 60}, {50, 80}};
  const NormalizedPoints n = normalizePoints(pts);
  Eigen::Vector2d c = Eigen::Vector2d::Zero();
  double d = 0.0;
  for (size_t i = 0; i < pts.size(); ++i) {
    c += n.points[i];
    d += n.points[i].norm();
    EXPECT_LT(((n.T * pts[i].homogeneous()).hnormalized() - n.points[i]).norm(), 1e-12);
  }
  EXPECT_LT(c.norm(), 1e-12);
  EXPECT_NEAR(d / pts.size(), std::sqrt(2.0), 1e-12);
  EXPECT_THROW(normalizePoints({{1, 1}, {1, 1}}), std::invalid_argument);
  EXPECT_THROW(normalizePoints({}), std::invalid_argument);
}

TEST(RansacSampling, SetsHoldDistinctValidIndicesAndAreReproducible) {
  const SampleSets a = drawSampleSets(20, 8, 50, 7);
  const SampleSets b = drawSampleSets(20, 8, 50, 7);
  EXPECT_EQ(a.indices, b.indices);
  ASSERT_EQ(a.indices.size(), 400u);
  for (int s = 0; s < a.count; ++s) {
    std::vector<int> set(a.set(s), a.set(s) + 8);
    std::sort(set.begin(), set.end());
    EXPECT_EQ(std::unique(set.begin(), set.end()), set.end());
    EXPECT_GE(set.front(), 0);
    EXPECT_LT(set.back(), 20);
  }
  EXPECT_NE(drawSampleSets(20, 8, 50, 8).indices, a.indices);
  EXPECT_THROW(drawSampleSets(5, 8, 10, 1), std::invalid_argument);
}

TEST(Homography, DltIsExactOnAPlane) {
  const auto s = makeTwoViewScene(kMotion, noiseFree(true));
  const auto H = estimateHomographyDlt(s.ref_px, s.cur_px);
  ASSERT_TRUE(H.has_value());
  double worst = 0.0;
  for (size_t i = 0; i < s.ref_px.size(); ++i) {
    worst = std::max(worst, ((*H * s.ref_px[i].homogeneous()).hnormalized() - s.cur_px[i]).norm());
  }
  EXPECT_LT(worst, 1e-6);
}

TEST(Homography, DegenerateAndInvalidInput) {
  const std::vector<Eigen::Vector2d> line = {{0, 0}, {1, 1}, {2, 2}, {3, 3}, {4, 4}};
  const std::vector<Eigen::Vector2d> other = {{5, 1}, {6, 3}, {1, 7}, {9, 2}, {3, 3}};
  EXPECT_FALSE(estimateHomographyDlt(line, other).has_value());
  const std::vector<Eigen::Vector2d> three(other.begin(), other.begin() + 3);
  EXPECT_FALSE(estimateHomographyDlt(three, three).has_value());
  EXPECT_THROW(estimateHomographyDlt(line, three), std::invalid_argument);
  std::vector<Eigen::Vector2d> bad = other;
  bad[2].x() = std::nan("");
  EXPECT_THROW(estimateHomographyDlt(line, bad), std::invalid_argument);
}

TEST(Homography, RansacFindsThePlaneDespiteOutliers) {
  SceneOptions o;
  o.planar = true;
  const auto s = makeTwoViewScene(kMotion, o);
  const SampleSets sets = drawSampleSets(static_cast<int>(s.ref_px.size()), 8, 200, 1);
  const HomographyEstimate h = findHomographyRansac(s.ref_px, s.cur_px, sets, 1.0);
  ASSERT_TRUE(h.valid);
  int true_inliers = 0, flagged_outliers = 0;
  for (size_t i = 0; i < s.outlier.size(); ++i) {
    if (!s.outlier[i] && h.score.inliers[i]) ++true_inliers;
    if (s.outlier[i] && h.score.inliers[i]) ++flagged_outliers;
  }
  const int num_true = static_cast<int>(std::count(s.outlier.begin(), s.outlier.end(), 0));
  EXPECT_GT(true_inliers, 0.9 * num_true);
  EXPECT_LE(flagged_outliers, 2);
}

TEST(Homography, DecompositionContainsTheTrueMotion) {
  const auto s = makeTwoViewScene(kMotion, noiseFree(true));
  const auto H = estimateHomographyDlt(s.ref_px, s.cur_px);
  ASSERT_TRUE(H.has_value());
  const auto motions = decomposeHomography(*H, s.K);
  ASSERT_FALSE(motions.empty());
  const Eigen::Vector3d t_true = kMotion.translation().normalized();
  double best = 1e9;
  for (const auto& m : motions) {
    best = std::min(best, rotationDistance(m.cam2_from_cam1, kMotion) +
                              (m.cam2_from_cam1.translation() - t_true).norm());
  }
  EXPECT_LT(best, 1e-6);
}

TEST(Fundamental, EightPointIsExactAndRankTwo) {
  const auto s = makeTwoViewScene(kMotion, noiseFree(false));
  const auto F = estimateFundamentalEightPoint(s.ref_px, s.cur_px);
  ASSERT_TRUE(F.has_value());
  EXPECT_LT(sameUpToSign(*F, trueFundamental(kMotion, s.K)), 1e-6);
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(*F);
  EXPECT_LT(svd.singularValues()(2), 1e-12 * svd.singularValues()(0));
  const TwoViewScore score = scoreFundamental(*F, s.ref_px, s.cur_px, 1.0);
  EXPECT_EQ(score.num_inliers, static_cast<int>(s.ref_px.size()));
  // A perfect fit scores the full offset twice per match.
  EXPECT_NEAR(score.score, 2.0 * 5.991 * s.ref_px.size(), 1e-3);
}

TEST(Fundamental, RansacRejectsOutliers) {
  const auto s = makeTwoViewScene(kMotion, SceneOptions{});
  const SampleSets sets = drawSampleSets(static_cast<int>(s.ref_px.size()), 8, 200, 1);
  const FundamentalEstimate f = findFundamentalRansac(s.ref_px, s.cur_px, sets, 1.0);
  ASSERT_TRUE(f.valid);
  int true_inliers = 0, flagged_outliers = 0;
  for (size_t i = 0; i < s.outlier.size(); ++i) {
    if (!s.outlier[i] && f.score.inliers[i]) ++true_inliers;
    if (s.outlier[i] && f.score.inliers[i]) ++flagged_outliers;
  }
  const int num_true = static_cast<int>(std::count(s.outlier.begin(), s.outlier.end(), 0));
  // Noise 0.7 px in each image is ~1 px on the point-line distance, the 95 % gate of sigma = 1.
  EXPECT_GT(true_inliers, 0.85 * num_true);
  // A random point lies near its epipolar line now and then: allow a few.
  EXPECT_LT(flagged_outliers, 0.1 * (s.outlier.size() - num_true));
  EXPECT_LT(sameUpToSign(f.F21, trueFundamental(kMotion, s.K)), 0.05);
}

TEST(Essential, OneOfFourDecompositionsIsTheTrueMotion) {
  const Eigen::Matrix3d E = skew(kMotion.translation()) * kMotion.rotationMatrix();
  const auto candidates = decomposeEssential(-3.0 * E);  // any scale and sign
  int matches = 0;
  for (const SE3d& c : candidates) {
    EXPECT_NEAR(c.translation().norm(), 1.0, 1e-12);
    if (rotationDistance(c, kMotion) < 1e-9 &&
        (c.translation() - kMotion.translation().normalized()).norm() < 1e-9) {
      ++matches;
    }
  }
  EXPECT_EQ(matches, 1);
}

std::vector<Eigen::Vector2d> normalized(const std::vector<Eigen::Vector2d>& px,
                                        const Eigen::Matrix3d& K) {
  std::vector<Eigen::Vector2d> out;
  for (const auto& p : px) out.push_back((K.inverse() * p.homogeneous()).hnormalized());
  return out;
}

TEST(RelativePoseRefinement, ConvergesToTheTrueMotion) {
  const auto s = makeTwoViewScene(kMotion, noiseFree(false));
  const auto x1 = normalized(s.ref_px, s.K), x2 = normalized(s.cur_px, s.K);
  const Eigen::Matrix3d E = skew(kMotion.translation().normalized()) * kMotion.rotationMatrix();
  EXPECT_LT(std::abs(sampsonDistance(E, x1[1], x2[1])), 1e-12);

  const SE3d start = SE3d::exp((Vector6d() << 0.05, -0.03, 0.0, 0.01, -0.01, 0.015).finished()) *
                     SE3d(kMotion.rotation(), kMotion.translation().normalized());
  const SE3d refined = refineRelativePose(start, x1, x2, 0.0, 50);
  EXPECT_NEAR(refined.translation().norm(), 1.0, 1e-12);
  EXPECT_LT(rotationDistance(refined, kMotion), 1e-7);
  EXPECT_LT(test::angleDeg(refined.translation(), kMotion.translation()), 1e-5);
  EXPECT_THROW(refineRelativePose(start, x1, std::span(x2).first(3)), std::invalid_argument);
}

TEST(RelativePoseRefinement, RobustLossResistsOutliers) {
  SceneOptions o;
  o.noise_px = 0.5;
  o.outlier_fraction = 0.1;
  o.num_points = 200;
  const auto s = makeTwoViewScene(kMotion, o);
  const auto x1 = normalized(s.ref_px, s.K), x2 = normalized(s.cur_px, s.K);
  const SE3d start = SE3d::exp((Vector6d() << 0.05, -0.03, 0.0, 0.01, -0.01, 0.015).finished()) *
                     SE3d(kMotion.rotation(), kMotion.translation().normalized());
  const SE3d robust = refineRelativePose(start, x1, x2, 2.0 / 520.0, 50);
  const SE3d plain = refineRelativePose(start, x1, x2, 0.0, 50);
  const double robust_t = test::angleDeg(robust.translation(), kMotion.translation());
  const double plain_t = test::angleDeg(plain.translation(), kMotion.translation());
  EXPECT_LT(radToDeg(rotationDistance(robust, kMotion)), 0.1);
  EXPECT_LT(robust_t, 0.5);
  EXPECT_LT(robust_t, plain_t);
}

}  // namespace
}  // namespace edgeslam
