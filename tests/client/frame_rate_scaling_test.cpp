// Keyframe frame counts are given for a 30 fps camera and follow a slower camera's rate: one
// helper for the defaults, the adaptation's Table I rows and the segmentation refresh.
#include "client/frame_rate_scaling.h"

#include <gtest/gtest.h>

namespace edgeslam {
namespace {

TEST(FrameRateScaling, CountsShrinkWithASlowerCameraOnly) {
  EXPECT_DOUBLE_EQ(rateAgainst30Fps(0.0), 1.0);  // unknown rate: as given
  EXPECT_DOUBLE_EQ(rateAgainst30Fps(60.0), 1.0);
  EXPECT_DOUBLE_EQ(rateAgainst30Fps(10.0), 1.0 / 3.0);
  EXPECT_EQ(framesAtCameraRate(40, 10.0), 13);
  EXPECT_EQ(framesAtCameraRate(1, 10.0), 1);  // never rounded to off
  EXPECT_EQ(framesAtCameraRate(0, 10.0), 0);  // off stays off
  EXPECT_EQ(framesAtCameraRate(40, 30.0), 40);
}

TEST(FrameRateScaling, KeyFrameGapsDropTheMinimumBelow15Fps) {
  KeyFrameParameters kf;
  setKeyFrameGaps(kf, 10, 40, 30.0);
  EXPECT_EQ(kf.fmin, 10);
  EXPECT_EQ(kf.fmax, 40);
  setKeyFrameGaps(kf, 10, 40, 20.0);
  EXPECT_EQ(kf.fmin, 7);
  EXPECT_EQ(kf.fmax, 27);
  setKeyFrameGaps(kf, 10, 40, 10.0);  // KITTI
  EXPECT_EQ(kf.fmin, 0);
  EXPECT_EQ(kf.fmax, 13);
  setKeyFrameGaps(kf, 0, 1, 10.0);
  EXPECT_EQ(kf.fmax, 1);
}

}  // namespace
}  // namespace edgeslam
