#include "eval/rpe.h"

#include <gtest/gtest.h>

#include <numbers>

#include "eval/eval_error.h"
#include "synthetic_trajectories.h"

namespace edgeslam {
namespace {

// Straight line along x at `speed` metres per frame, 10 frames per second, with yaw `yaw_rate`
// radians per frame.
Trajectory straightLine(std::size_t n, double speed, double yaw_rate = 0.0) {
  Trajectory t;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = static_cast<double>(i);
    t.push_back({0.1 * s, test::yaw(yaw_rate * s, Eigen::Vector3d(speed * s, 0, 0))});
  }
  return t;
}

RpeResult rpe(const Trajectory& gt, const Trajectory& est, double delta, DeltaUnit unit,
              AlignMode align = AlignMode::kNone) {
  return computeRpe(test::pairsOf(gt, est), {delta, unit, align});
}

TEST(Rpe, ConstantVelocityErrorOverFrames) {
  const RpeResult r = rpe(straightLine(50, 1.0), straightLine(50, 1.1), 5, DeltaUnit::kFrames);
  EXPECT_EQ(r.errors.size(), 45U);
  EXPECT_NEAR(r.translation.rmse, 0.5, 1e-12);
  EXPECT_NEAR(r.translation.min, 0.5, 1e-12);
  EXPECT_NEAR(r.translation.max, 0.5, 1e-12);
  EXPECT_NEAR(r.rotation.max, 0.0, 1e-12);
  EXPECT_EQ(r.errors.front().second, 5U);
}

TEST(Rpe, SecondsDeltaUsesFirstPoseAtLeastThatMuchLater) {
  // 1 s = 10 frames at 10 Hz, despite 0.1 * 10 not adding up exactly in binary.
  const RpeResult r = rpe(straightLine(50, 1.0), straightLine(50, 1.1), 1.0, DeltaUnit::kSeconds);
  EXPECT_EQ(r.errors.size(), 40U);
  EXPECT_EQ(r.errors.front().second, 10U);
  EXPECT_NEAR(r.translation.mean, 1.0, 1e-9);
  // 1.05 s needs 11 frames.
  EXPECT_EQ(rpe(straightLine(50, 1.0), straightLine(50, 1.1), 1.05, DeltaUnit::kSeconds)
                .errors.front()
                .second,
            11U);
}

TEST(Rpe, MetresDeltaFollowsGroundTruthPathLength) {
  // Ground truth moves 2 m per frame: 5 m needs 3 frames (6 m), where the estimate errs 0.6 m.
  const RpeResult r = rpe(straightLine(30, 2.0), straightLine(30, 2.2), 5.0, DeltaUnit::kMetres);
  EXPECT_EQ(r.errors.front().second, 3U);
  EXPECT_EQ(r.errors.size(), 27U);
  EXPECT_NEAR(r.translation.rmse, 0.6, 1e-9);
}

TEST(Rpe, ConstantYawRateDriftGivesRotationError) {
  const double rate = 0.002;  // rad per frame
  const RpeResult r =
      rpe(straightLine(40, 1.0), straightLine(40, 1.0, rate), 10, DeltaUnit::kFrames);
  const double expected_deg = 10 * rate * 180.0 / std::numbers::pi;
  EXPECT_NEAR(r.rotation.min, expected_deg, 1e-9);
  EXPECT_NEAR(r.rotation.max, expected_deg, 1e-9);
  EXPECT_NEAR(r.rotation.rmse, expected_deg, 1e-9);
}

TEST(Rpe, Sim3AlignmentRemovesScale) {
  const Trajectory gt = test::wavyTrajectory(60);
  Trajectory est = gt;
  for (StampedPose& p : est) p.pose.setTranslation(2.0 * p.pose.translation());
  EXPECT_GT(rpe(gt, est, 3, DeltaUnit::kFrames).translation.rmse, 0.1);
  const RpeResult r = rpe(gt, est, 3, DeltaUnit::kFrames, AlignMode::kSim3);
  EXPECT_NEAR(r.scale, 0.5, 1e-9);
  EXPECT_LT(r.translation.rmse, 1e-9);
  EXPECT_LT(r.rotation.rmse, 1e-6);
}

TEST(Rpe, RejectsBadDeltas) {
  const Trajectory t = straightLine(10, 1.0);
  EXPECT_THROW(rpe(t, t, 10, DeltaUnit::kFrames), EvalError);
  EXPECT_THROW(rpe(t, t, 1.5, DeltaUnit::kFrames), EvalError);
  EXPECT_THROW(rpe(t, t, -1, DeltaUnit::kSeconds), EvalError);
  EXPECT_THROW(rpe(t, t, 100, DeltaUnit::kMetres), EvalError);
  EXPECT_THROW(parseDeltaUnit("furlongs"), EvalError);
  EXPECT_EQ(parseDeltaUnit("meters"), DeltaUnit::kMetres);
}

}  // namespace
}  // namespace edgeslam
