#include "geometry/sim3_solver.h"

#include <gtest/gtest.h>

#include <random>
#include <stdexcept>

#include "geometry/synthetic_scene.h"

namespace edgeslam {
namespace {

using test::degToRad;
using test::radToDeg;
using test::syntheticK;

Eigen::Matrix3d otherK() {
  Eigen::Matrix3d K;
  K << 600.0, 0.0, 330.0, 0.0, 590.0, 250.0, 0.0, 0.0, 1.0;
  return K;
}

struct Sim3Scene {
  Sim3d cam1_from_cam2;
  std::vector<Sim3Match> matches;
  std::vector<char> outlier;
};

// Points seen by keyframe 2 at 1.5-6 m, mapped into keyframe 1 by the true similarity, observed
// in both with pixel noise; outliers pair a point with an unrelated one.
Sim3Scene makeSim3Scene(double scale, int n, double outlier_fraction, unsigned seed) {
  Sim3Scene s;
  s.cam1_from_cam2 = Sim3d(scale,
                           Eigen::Quaterniond(Eigen::AngleAxisd(
                               degToRad(20.0), Eigen::Vector3d(0.2, 1.0, 0.1).normalized())),
                           Eigen::Vector3d(0.3, -0.1, 0.2));
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(100.0, 540.0), uy(80.0, 400.0), depth(1.5, 6.0);
  std::normal_distribution<double> noise(0.0, 0.7);
  const Eigen::Matrix3d K1 = otherK(), K2 = syntheticK();
  while (static_cast<int>(s.matches.size()) < n) {
    const Eigen::Vector3d X2 =
        (K2.inverse() * Eigen::Vector2d(ux(rng), uy(rng)).homogeneous()) * depth(rng);
    const Eigen::Vector3d X1 = s.cam1_from_cam2 * X2;
    if (X1.z() < 0.5) continue;
    Sim3Match m;
    m.point1 = X1;
    m.point2 = X2;
    m.pixel1 = (K1 * X1).hnormalized() + Eigen::Vector2d(noise(rng), noise(rng));
    m.pixel2 = (K2 * X2).hnormalized() + Eigen::Vector2d(noise(rng), noise(rng));
    s.matches.push_back(m);
    s.outlier.push_back(0);
  }
  const int outliers = static_cast<int>(outlier_fraction * n);
  for (int i = 0; i < outliers; ++i) {
    const int k = i * n / outliers;
    // Another point of keyframe 1, with its own observation: consistent there, wrong as a pair.
    Eigen::Vector3d X1;
    do {
      X1 = (K1.inverse() * Eigen::Vector2d(ux(rng), uy(rng)).homogeneous()) * depth(rng);
    } while ((X1 - s.matches[k].point1).norm() < 0.5);
    s.matches[k].point1 = X1;
    s.matches[k].pixel1 = (K1 * X1).hnormalized();
    s.outlier[k] = 1;
  }
  return s;
}

// Triangulated map points carry depth noise: perturb them along their viewing ray.
void addDepthNoise(Sim3Scene& s, double relative, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, relative);
  for (auto& m : s.matches) {
    m.point1 *= 1.0 + n(rng);
    m.point2 *= 1.0 + n(rng);
  }
}

TEST(Sim3Solver, UmeyamaIsExactWithoutNoise) {
  const Sim3Scene s = makeSim3Scene(2.5, 20, 0.0, 1);
  std::vector<Eigen::Vector3d> p1, p2;
  for (const auto& m : s.matches) {
    p1.push_back(m.point1);
    p2.push_back(m.point2);
  }
  const auto S = alignUmeyama(p1, p2, false);
  ASSERT_TRUE(S.has_value());
  EXPECT_NEAR(S->scale(), 2.5, 1e-9);
  EXPECT_LT(S->rotation().angularDistance(s.cam1_from_cam2.rotation()), 1e-9);
  EXPECT_LT((S->translation() - s.cam1_from_cam2.translation()).norm(), 1e-9);

  const std::vector<Eigen::Vector3d> two(p1.begin(), p1.begin() + 2);
  EXPECT_FALSE(alignUmeyama(two, two, false).has_value());
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 5; ++i) line.emplace_back(i, 2.0 * i, 1.0 + i);
  EXPECT_FALSE(alignUmeyama(line, line, false).has_value());
  EXPECT_THROW(alignUmeyama(p1, two, false), std::invalid_argument);
}

TEST(Sim3Solver, RecoversSimilarityWithOutliers) {
  for (double scale : {0.4, 1.0, 3.0}) {
    Sim3Scene s = makeSim3Scene(scale, 120, 0.3, 7);
    addDepthNoise(s, 0.003, 8);
    const Sim3Result r = solveSim3Ransac(s.matches, otherK(), syntheticK());
    ASSERT_TRUE(r.success) << r.reason;
    const Sim3d& S = r.cam1_from_cam2;
    EXPECT_NEAR(S.scale() / scale, 1.0, 0.02) << "scale " << scale;
    EXPECT_LT(radToDeg(S.rotation().angularDistance(s.cam1_from_cam2.rotation())), 0.5);
    EXPECT_LT((S.translation() - s.cam1_from_cam2.translation()).norm(), 0.05 * scale + 0.02);
    int accepted_outliers = 0, missed = 0;
    for (size_t i = 0; i < s.outlier.size(); ++i) {
      if (s.outlier[i] && r.inliers[i]) ++accepted_outliers;
      if (!s.outlier[i] && !r.inliers[i]) ++missed;
    }
    EXPECT_LE(accepted_outliers, 1);
    EXPECT_LT(missed, 0.1 * 84) << "scale " << scale << " inliers " << r.num_inliers;
    EXPECT_GT(r.iterations, 0);
  }
}

TEST(Sim3Solver, FixedScaleReturnsUnitScaleAndTheRigidMotion) {
  Sim3Scene s = makeSim3Scene(1.0, 100, 0.25, 11);
  addDepthNoise(s, 0.005, 12);
  Sim3SolverOptions fixed;
  fixed.fix_scale = true;
  const Sim3Result r = solveSim3Ransac(s.matches, otherK(), syntheticK(), fixed);
  ASSERT_TRUE(r.success) << r.reason;
  EXPECT_EQ(r.cam1_from_cam2.scale(), 1.0);
  EXPECT_LT(radToDeg(r.cam1_from_cam2.rotation().angularDistance(s.cam1_from_cam2.rotation())),
            0.5);
  EXPECT_LT((r.cam1_from_cam2.translation() - s.cam1_from_cam2.translation()).norm(), 0.05);

  // The same solver without the constraint on scaled data returns the scale; with it, it must
  // not invent one even when the data disagree.
  Sim3Scene scaled = makeSim3Scene(2.0, 100, 0.0, 13);
  const Sim3Result forced = solveSim3Ransac(scaled.matches, otherK(), syntheticK(), fixed);
  EXPECT_EQ(forced.cam1_from_cam2.scale(), 1.0);
}

TEST(Sim3Solver, ReportsDegenerateInputAndRejectsInvalid) {
  const Eigen::Matrix3d K = syntheticK();
  Sim3Scene s = makeSim3Scene(1.5, 10, 0.0, 21);
  Sim3Result r = solveSim3Ransac(s.matches, K, K);
  EXPECT_FALSE(r.success);
  EXPECT_NE(r.reason.find("matches"), std::string::npos) << r.reason;

  std::vector<Sim3Match> collinear;
  for (int i = 0; i < 40; ++i) {
    Sim3Match m;
    m.point1 = m.point2 = Eigen::Vector3d(0.01 * i, 0.0, 2.0 + 0.05 * i);
    m.pixel1 = m.pixel2 = (K * m.point1).hnormalized();
    collinear.push_back(m);
  }
  r = solveSim3Ransac(collinear, K, K);
  EXPECT_FALSE(r.success);
  EXPECT_FALSE(r.reason.empty());

  Sim3Scene bad = makeSim3Scene(1.0, 30, 0.0, 22);
  bad.matches[4].sigma2_px = 0.0;
  EXPECT_THROW(solveSim3Ransac(bad.matches, K, K), std::invalid_argument);
  bad.matches[4].sigma2_px = 1.0;
  bad.matches[5].point1.x() = std::nan("");
  EXPECT_THROW(solveSim3Ransac(bad.matches, K, K), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
