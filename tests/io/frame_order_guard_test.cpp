#include "io/frame_order_guard.h"

#include <gtest/gtest.h>

#include <limits>

namespace edgeslam {
namespace {

TEST(FrameOrderGuard, AcceptsIncreasingTimesAndCountsEachKindOfDisorder) {
  FrameOrderGuard guard;
  EXPECT_FALSE(guard.check(0.0));
  EXPECT_FALSE(guard.check(0.1));
  EXPECT_EQ(guard.check(0.1), FrameOrderRejection::kDuplicateTimestamp);
  EXPECT_EQ(guard.check(0.05), FrameOrderRejection::kTimestampBackwards);
  EXPECT_EQ(guard.check(std::numeric_limits<double>::quiet_NaN()), FrameOrderRejection::kNotFinite);
  // A stale frame does not move the reference back: 0.08 is still behind 0.1.
  EXPECT_EQ(guard.check(0.08), FrameOrderRejection::kTimestampBackwards);
  EXPECT_FALSE(guard.check(0.2));
  EXPECT_EQ(guard.duplicates(), 1u);
  EXPECT_EQ(guard.backwards(), 2u);
  EXPECT_EQ(guard.notFinite(), 1u);
  EXPECT_EQ(guard.rejected(), 4u);
}

}  // namespace
}  // namespace edgeslam
