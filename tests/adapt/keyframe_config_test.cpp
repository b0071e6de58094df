#include "adapt/keyframe_config.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

TEST(AdaptationTable, HoldsThePapersTableOne) {
  const auto& t = adaptationTable();
  EXPECT_EQ(t[0].config, (KeyframeConfig{10, 40, 0.3, 0.9, 8, 0.8}));
  EXPECT_EQ(t[1].config, (KeyframeConfig{20, 50, 0.3, 0.9, 6, 0.8}));
  EXPECT_EQ(t[2].config, (KeyframeConfig{20, 60, 0.4, 0.9, 6, 0.8}));
  EXPECT_EQ(t[3].config, (KeyframeConfig{30, 70, 0.5, 0.8, 4, 0.7}));
  EXPECT_EQ(t[4].config, (KeyframeConfig{40, 80, 0.5, 0.7, 4, 0.6}));
  EXPECT_EQ(t[kDefaultAdaptationRow].config, KeyframeConfig{});  // the paper's defaults
}

TEST(AdaptationTable, IntervalsAreOpenBelowClosedAbove) {
  EXPECT_EQ(adaptationRowFor(0.0), 0u);
  EXPECT_EQ(adaptationRowFor(-3.0), 0u);
  EXPECT_EQ(adaptationRowFor(10.0), 0u);
  EXPECT_EQ(adaptationRowFor(10.01), 1u);
  EXPECT_EQ(adaptationRowFor(15.0), 1u);
  EXPECT_EQ(adaptationRowFor(15.5), 2u);
  EXPECT_EQ(adaptationRowFor(35.0), 2u);
  EXPECT_EQ(adaptationRowFor(35.1), 3u);
  EXPECT_EQ(adaptationRowFor(50.0), 3u);
  EXPECT_EQ(adaptationRowFor(50.1), 4u);
  EXPECT_EQ(adaptationRowFor(299.0), 4u);
  EXPECT_EQ(adaptationRowFor(5000.0), 4u);  // >= 300 stays at the last row
  EXPECT_EQ(adaptationRowFor(INFINITY), 4u);
  EXPECT_THROW(adaptationRowFor(NAN), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
