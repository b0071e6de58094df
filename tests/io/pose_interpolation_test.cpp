#include "io/pose_interpolation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace edgeslam {
namespace {

SE3d yawPose(double yaw, const Eigen::Vector3d& t) {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ())), t};
}

TEST(InterpolatePose, ExactSampleIsReturnedAsIs) {
  const Trajectory trajectory = {{1.0, yawPose(0.1, {1, 2, 3})}, {1.01, yawPose(0.2, {2, 2, 3})}};
  const auto pose = interpolatePose(trajectory, 1.01, 0.02);
  ASSERT_TRUE(pose);
  EXPECT_NEAR((pose->translation() - Eigen::Vector3d(2, 2, 3)).norm(), 0.0, 1e-12);
}

TEST(InterpolatePose, InterpolatesTranslationLinearlyAndRotationBySlerp) {
  const Trajectory trajectory = {{1.0, yawPose(0.0, {0, 0, 0})}, {1.01, yawPose(0.4, {1, -2, 4})}};
  const auto pose = interpolatePose(trajectory, 1.0025, 0.02);
  ASSERT_TRUE(pose);
  EXPECT_NEAR((pose->translation() - Eigen::Vector3d(0.25, -0.5, 1.0)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(rotationDistance(*pose, yawPose(0.1, {0, 0, 0})), 0.0, 1e-9);
}

TEST(InterpolatePose, HandlesQuaternionSignFlipsAlongTheShortArc) {
  SE3d flipped = yawPose(0.2, {0, 0, 0});
  flipped.setRotation(Eigen::Quaterniond(-flipped.rotation().coeffs()));
  const Trajectory trajectory = {{0.0, yawPose(0.0, {0, 0, 0})}, {0.01, flipped}};
  const auto pose = interpolatePose(trajectory, 0.005, 0.02);
  ASSERT_TRUE(pose);
  EXPECT_NEAR(rotationDistance(*pose, yawPose(0.1, {0, 0, 0})), 0.0, 1e-9);
}

TEST(InterpolatePose, NoPoseOutsideTheTrajectoryOrAcrossAGap) {
  const Trajectory trajectory = {{1.0, SE3d()}, {1.01, SE3d()}, {1.5, SE3d()}, {1.51, SE3d()}};
  EXPECT_FALSE(interpolatePose(trajectory, 0.999, 0.02));  // before the first sample
  EXPECT_FALSE(interpolatePose(trajectory, 1.52, 0.02));   // after the last
  EXPECT_FALSE(interpolatePose(trajectory, 1.2, 0.02));    // inside a 0.49 s gap
  EXPECT_FALSE(interpolatePose(trajectory, 1.03, 0.02));   // 0.02 s past the left sample
  EXPECT_TRUE(interpolatePose(trajectory, 1.005, 0.02));
  EXPECT_FALSE(interpolatePose({}, 1.0, 0.02));
}

TEST(InterpolatePose, SortByTimeOrdersSamples) {
  Trajectory trajectory = {{3.0, SE3d()}, {1.0, SE3d()}, {2.0, SE3d()}};
  sortByTime(trajectory);
  EXPECT_EQ(trajectory[0].timestamp, 1.0);
  EXPECT_EQ(trajectory[2].timestamp, 3.0);
}

}  // namespace
}  // namespace edgeslam
