#include "features/rotation_histogram.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

TEST(RotationHistogram, KeepsTheDominantRotation) {
  RotationHistogram histogram;
  int id = 0;
  // 100 matches turned by about 40 degrees (across the wrap-around too), 5 random outliers.
  for (int i = 0; i < 100; ++i, ++id) histogram.add(340.f + 0.02f * i, 20.f + 0.02f * i, id);
  const std::vector<float> outliers = {120.f, 200.f, 260.f, 300.f, 170.f};
  for (const float a : outliers) histogram.add(0.f, a, id++);
  auto bad = histogram.inconsistent();
  std::sort(bad.begin(), bad.end());
  EXPECT_EQ(bad, (std::vector<int>{100, 101, 102, 103, 104}));
  EXPECT_EQ(histogram.consistent().size(), 100u);
}

TEST(RotationHistogram, KeepsSecondAndThirdBinsOnlyWhenSubstantial) {
  RotationHistogram histogram(30);
  int id = 0;
  for (int i = 0; i < 100; ++i) histogram.add(0.f, 1.f, id++);  // bin 0
  for (int i = 0; i < 20; ++i) histogram.add(0.f, 13.f, id++);  // bin 1: 20% of the peak
  for (int i = 0; i < 5; ++i) histogram.add(0.f, 359.f, id++);  // bin 29: 5%
  EXPECT_EQ(histogram.consistent().size(), 120u);
  EXPECT_EQ(histogram.inconsistent().size(), 5u);
}

TEST(RotationHistogram, RejectsBadInput) {
  EXPECT_THROW(RotationHistogram(0), std::invalid_argument);
  RotationHistogram histogram;
  EXPECT_THROW(histogram.add(std::nanf(""), 0.f, 1), std::invalid_argument);
  EXPECT_TRUE(histogram.consistent().empty());
}

}  // namespace
}  // namespace edgeslam
