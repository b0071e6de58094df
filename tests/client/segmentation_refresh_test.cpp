#include "client/segmentation_refresh.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace edgeslam {
namespace {

TEST(SegmentationRefresh, FollowsTheMasksDelayWithinItsBounds) {
  const SegmentationRefreshOptions options;                         // 6..12 frames, 4x the delay
  EXPECT_EQ(segmentationRefreshFrames(options, std::nullopt), 12);  // nothing back yet
  EXPECT_EQ(segmentationRefreshFrames(options, 0), 6);
  EXPECT_EQ(segmentationRefreshFrames(options, 1), 6);
  EXPECT_EQ(segmentationRefreshFrames(options, 2), 8);
  EXPECT_EQ(segmentationRefreshFrames(options, 3), 12);
  EXPECT_EQ(segmentationRefreshFrames(options, 120), 12);  // a mask past the history
}

TEST(SegmentationRefresh, FixedOrOffAndBadBounds) {
  SegmentationRefreshOptions fixed;
  fixed.min_frames = fixed.max_frames = 9;
  EXPECT_EQ(segmentationRefreshFrames(fixed, 1), 9);
  EXPECT_EQ(segmentationRefreshFrames(fixed, 7), 9);
  SegmentationRefreshOptions off;
  off.max_frames = 0;
  EXPECT_NO_THROW(validate(off));
  EXPECT_EQ(segmentationRefreshFrames(off, 1), 0);
  EXPECT_EQ(segmentationRefreshFrames(off, std::nullopt), 0);

  SegmentationRefreshOptions bad;
  bad.min_frames = 13;
  EXPECT_THROW(validate(bad), std::invalid_argument);
  bad = {};
  bad.max_frames = -1;
  EXPECT_THROW(validate(bad), std::invalid_argument);
  bad = {};
  bad.duty_factor = 0;
  EXPECT_THROW(validate(bad), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
