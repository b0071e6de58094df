#include <gtest/gtest.h>

#include <stdexcept>

#include "io/frame_range.h"

namespace edgeslam {
namespace {

TEST(FrameRange, ParsesInclusiveRanges) {
  const FrameRange range = parseFrameRange("10-39");
  EXPECT_EQ(range.first, 10u);
  EXPECT_EQ(range.last, 39u);
  EXPECT_EQ(range.count(), 30u);
  EXPECT_EQ(parseFrameRange("0-0").count(), 1u);
}

TEST(FrameRange, RejectsMalformedText) {
  for (const char* text : {"", "10", "-5", "5-", "a-b", "3-1", "1--2", "1-2-3", " 1-2", "1.5-3"}) {
    EXPECT_THROW(parseFrameRange(text), std::invalid_argument) << text;
  }
  try {
    parseFrameRange("30-20");
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("30-20"), std::string::npos);
  }
}

TEST(FrameRange, ParsesSeveralRanges) {
  const std::vector<FrameRange> ranges = parseFrameRanges("0-200,375-999");
  ASSERT_EQ(ranges.size(), 2u);
  EXPECT_EQ(ranges[0].first, 0u);
  EXPECT_EQ(ranges[0].last, 200u);
  EXPECT_EQ(ranges[1].first, 375u);
  EXPECT_EQ(ranges[1].last, 999u);
  EXPECT_EQ(parseFrameRanges("5-9").size(), 1u);
  for (const char* text : {"", ",", "0-10,", ",0-10", "0-10,,20-30", "0-10;20-30", "0-10,30-20"}) {
    EXPECT_THROW(parseFrameRanges(text), std::invalid_argument) << text;
  }
}

TEST(FrameRange, CheckAgainstSequenceLength) {
  EXPECT_NO_THROW(checkFrameRange({0, 99}, 100));
  EXPECT_THROW(checkFrameRange({0, 100}, 100), std::invalid_argument);
  EXPECT_THROW(checkFrameRange({0, 0}, 0), std::invalid_argument);
  try {
    checkFrameRange({50, 1200}, 1000);
    FAIL();
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("1000 frames"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace edgeslam
