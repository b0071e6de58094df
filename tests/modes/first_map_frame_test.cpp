// Which frames' poses are in the first map's frame, at their time and finally.
#include "modes/first_map_frame.h"

#include <gtest/gtest.h>

namespace edgeslam {
namespace {

TEST(FirstMapFrame, TheFirstMapsFramesAreAlwaysInIt) {
  FirstMapFrame frames;
  frames.noteProgress(10, 0);
  frames.currentMapJoinedFirst();  // nothing to join: tracking is in the first map
  EXPECT_TRUE(frames.inFirstAtFrameTime(3, 0));
  EXPECT_TRUE(frames.inFirstFinally(0));
}

TEST(FirstMapFrame, ANewMapJoinsFromTheFrameAfterTheOneBeingTracked) {
  FirstMapFrame frames;
  frames.noteProgress(100, 1);  // records 0-99; map 1 began some frames ago
  EXPECT_FALSE(frames.inFirstAtFrameTime(99, 1));
  EXPECT_FALSE(frames.inFirstFinally(1));
  frames.currentMapJoinedFirst();  // while record 100 may be in flight
  EXPECT_FALSE(frames.inFirstAtFrameTime(100, 1));
  EXPECT_TRUE(frames.inFirstAtFrameTime(101, 1));
  EXPECT_FALSE(frames.inFirstAtFrameTime(50, 1));
  EXPECT_TRUE(frames.inFirstFinally(1));
  // Told again (a later merge that moved it): the first join stands.
  frames.noteProgress(200, 1);
  frames.currentMapJoinedFirst();
  EXPECT_TRUE(frames.inFirstAtFrameTime(150, 1));
}

TEST(FirstMapFrame, AMapNeverJoinedStaysOutAndLaterMapsAreTheirOwn) {
  FirstMapFrame frames;
  frames.noteProgress(50, 1);
  frames.noteProgress(80, 2);  // map 1 lost too; map 2 began
  frames.currentMapJoinedFirst();
  EXPECT_FALSE(frames.inFirstFinally(1));
  EXPECT_FALSE(frames.inFirstAtFrameTime(90, 1));
  EXPECT_TRUE(frames.inFirstFinally(2));
  EXPECT_TRUE(frames.inFirstAtFrameTime(81, 2));
  EXPECT_FALSE(frames.inFirstFinally(3));
}

}  // namespace
}  // namespace edgeslam
