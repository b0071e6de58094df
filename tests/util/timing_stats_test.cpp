#include "util/timing_stats.h"

#include <gtest/gtest.h>

namespace edgeslam {
namespace {

TEST(SampleStats, PercentilesOfKnownSamples) {
  SampleStats stats;
  for (int i = 100; i >= 1; --i) stats.add(i);  // 1..100 in reverse order
  const PercentileSummary s = stats.summary();
  EXPECT_EQ(s.count, 100u);
  EXPECT_DOUBLE_EQ(s.median, 50.5);
  EXPECT_NEAR(s.p90, 90.1, 1e-9);
  EXPECT_NEAR(s.p99, 99.01, 1e-9);
  EXPECT_DOUBLE_EQ(s.max, 100.0);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
}

TEST(SampleStats, EmptyIsZero) {
  const PercentileSummary s = SampleStats{}.summary();
  EXPECT_EQ(s.count, 0u);
  EXPECT_EQ(s.median, 0.0);
}

TEST(Percentile, MatchesSummary) {
  EXPECT_DOUBLE_EQ(percentile({3.0, 1.0, 2.0}, 0.5), 2.0);
  EXPECT_DOUBLE_EQ(percentile({}, 0.5), 0.0);
  EXPECT_DOUBLE_EQ(percentile({1.0, 2.0}, 1.0), 2.0);
}

}  // namespace
}  // namespace edgeslam
