#include "eval/ate.h"

#include <gtest/gtest.h>

#include "synthetic_trajectories.h"

namespace edgeslam {
namespace {

const Sim3d kOffset(0.4, Eigen::Quaterniond(Eigen::AngleAxisd(-1.1, Eigen::Vector3d::UnitZ())),
                    Eigen::Vector3d(-2.0, 5.0, 1.0));

Trajectory transformed(const Trajectory& t, const Sim3d& s) {
  Trajectory out;
  for (const StampedPose& p : t) {
    out.push_back({p.timestamp, SE3d(s.rotation() * p.pose.rotation(), s * p.pose.translation())});
  }
  return out;
}

TEST(Ate, Sim3RecoversScaleOfScaledRotatedShiftedCopy) {
  const Trajectory gt = test::wavyTrajectory(150);
  const AteResult r = computeAte(test::pairsOf(gt, transformed(gt, kOffset)), AlignMode::kSim3);
  EXPECT_NEAR(r.alignment.scale(), 1.0 / 0.4, 1e-9);
  EXPECT_LT(r.translation.rmse, 1e-9);
  EXPECT_LT(r.translation.max, 1e-9);
  EXPECT_EQ(r.translation.count, 150U);
  EXPECT_EQ(r.errors.size(), 150U);
}

TEST(Ate, Se3CannotAbsorbScale) {
  const Trajectory gt = test::wavyTrajectory(150);
  const AteResult r = computeAte(test::pairsOf(gt, transformed(gt, kOffset)), AlignMode::kSe3);
  EXPECT_DOUBLE_EQ(r.alignment.scale(), 1.0);
  EXPECT_GT(r.translation.rmse, 1.0);
}

// Each ground-truth point appears twice, displaced by +n and -n: the noise has zero mean and no
// correlation with the positions, so the optimal alignment is the true one and every error is |n|.
TEST(Ate, Se3WithSymmetricNoiseGivesTheNoiseMagnitude) {
  const Trajectory base = test::wavyTrajectory(100);
  const Sim3d rigid(1.0, kOffset.rotation(), kOffset.translation());
  Trajectory gt;
  Trajectory est;
  const double noise = 0.05;
  for (std::size_t i = 0; i < base.size(); ++i) {
    const Eigen::Vector3d n =
        noise * Eigen::Vector3d(std::cos(0.3 * i), std::sin(0.3 * i), 0.5).normalized();
    for (const double sign : {1.0, -1.0}) {
      gt.push_back(base[i]);
      const Eigen::Vector3d noisy = base[i].pose.translation() + sign * n;
      est.push_back({base[i].timestamp, SE3d(base[i].pose.rotation(), rigid.inverse() * noisy)});
    }
  }
  const AteResult r = computeAte(test::pairsOf(gt, est), AlignMode::kSe3);
  EXPECT_NEAR(r.translation.rmse, noise, 1e-9);
  EXPECT_NEAR(r.translation.mean, noise, 1e-9);
  EXPECT_NEAR(r.translation.std, 0.0, 1e-7);
  EXPECT_LT(r.alignment.rotation().angularDistance(rigid.rotation()), 1e-9);
}

TEST(Ate, NoneMeasuresRawOffset) {
  const Trajectory gt = test::wavyTrajectory(20);
  const Sim3d shift(1.0, Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 3.0, 4.0));
  const AteResult r = computeAte(test::pairsOf(gt, transformed(gt, shift)), AlignMode::kNone);
  EXPECT_NEAR(r.translation.rmse, 5.0, 1e-12);
  EXPECT_NEAR(r.translation.min, 5.0, 1e-12);
}

}  // namespace
}  // namespace edgeslam
