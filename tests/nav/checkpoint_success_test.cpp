#include "nav/checkpoint_success.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

TEST(CheckpointSuccess, AnnouncedWithinTheRadiusOfTheTruthCounts) {
  const std::vector<Eigen::Vector3d> checkpoints = {{0, 0, 0}, {1, 0, 0}, {2, 0, 0}};
  const std::vector<Eigen::Vector3d> truth = {{0, 0, 0.1}, {1, 0, 0.3}, {2, 0, 0.6}};
  // Checkpoint 1 announced where the truth was 0.2 m away, checkpoint 2 where it was 0.7 m away,
  // checkpoint 3 never.
  const std::vector<AnnouncedCheckpoint> announced = {{0, {0, 0, 0.2}, {}}, {1, {1, 0, 0.7}, {}}};
  const CheckpointSuccess s = checkpointSuccess(checkpoints, announced, truth, 0.5);
  EXPECT_EQ(s.checkpoints, 3u);
  EXPECT_EQ(s.reached, 1u);
  EXPECT_NEAR(s.rate, 1.0 / 3.0, 1e-12);
  EXPECT_EQ(s.passed, 2u);  // the true path came within 0.5 m of the first two
  ASSERT_EQ(s.closest_m.size(), 3u);
  // Nearest on the true path between its last two frames (straight between frames).
  EXPECT_NEAR(s.closest_m[2], 0.6 / std::sqrt(1.09), 1e-12);
  ASSERT_EQ(s.announced_error_m.size(), 2u);
  EXPECT_NEAR(s.announced_error_m[1], 0.7, 1e-12);
}

TEST(CheckpointSuccess, TheTruePathBetweenTwoFramesCountsForACheckpointPassedBetweenThem) {
  // A car 1 m a frame: checkpoint 0.5 m lies between two frames, 0.5 m from each.
  const std::vector<Eigen::Vector3d> checkpoints = {{0, 0, 0.5}};
  const std::vector<Eigen::Vector3d> truth = {{0, 0, 0}, {0, 0, 1}};
  const std::vector<AnnouncedCheckpoint> passed = {{0, {0, 0, 1}, Eigen::Vector3d(0, 0, 0)}};
  const CheckpointSuccess s = checkpointSuccess(checkpoints, passed, truth, 0.3);
  EXPECT_EQ(s.reached, 1u);
  EXPECT_EQ(s.passed, 1u);
  EXPECT_NEAR(s.closest_m[0], 0.0, 1e-12);
  // Announced only on the frame after, from where the car had come the frame before: too late.
  const std::vector<AnnouncedCheckpoint> late = {{0, {0, 0, 2}, Eigen::Vector3d(0, 0, 1)}};
  EXPECT_EQ(checkpointSuccess(checkpoints, late, truth, 0.3).reached, 0u);
}

TEST(CheckpointSuccess, AnAnnouncementTwiceCountsOnceAndUnknownOnesAreRefused) {
  const std::vector<Eigen::Vector3d> checkpoints = {{0, 0, 0}};
  const std::vector<AnnouncedCheckpoint> twice = {{0, {0, 0, 0}, {}}, {0, {0, 0, 0.1}, {}}};
  EXPECT_EQ(checkpointSuccess(checkpoints, twice, {}, 0.5).reached, 1u);
  EXPECT_THROW(checkpointSuccess(checkpoints, {{3, {0, 0, 0}, {}}}, {}, 0.5),
               std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
