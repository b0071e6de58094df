#include "features/scale_levels.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

TEST(ScaleLevels, TablesArePowersOfTheFactor) {
  const ScaleLevels levels(8, 1.2);
  ASSERT_EQ(levels.numLevels(), 8);
  EXPECT_DOUBLE_EQ(levels.scale(0), 1.0);
  EXPECT_NEAR(levels.scale(7), std::pow(1.2, 7), 1e-12);
  for (int l = 0; l < 8; ++l) {
    EXPECT_NEAR(levels.sigma2(l), levels.scale(l) * levels.scale(l), 1e-12);
    EXPECT_NEAR(levels.invSigma2(l) * levels.sigma2(l), 1.0, 1e-12);
    EXPECT_NEAR(levels.invScale(l) * levels.scale(l), 1.0, 1e-12);
  }
}

TEST(ScaleLevels, PredictLevelFollowsDistance) {
  const ScaleLevels levels(8, 1.2);
  EXPECT_EQ(levels.predictLevel(2.0, 0, 2.0), 0);
  EXPECT_EQ(levels.predictLevel(2.0, 0, 2.0 / 1.2), 1);  // closer: seen larger, finer level up
  EXPECT_EQ(levels.predictLevel(2.0, 3, 2.0 * 1.2), 2);
  EXPECT_EQ(levels.predictLevel(2.0, 0, 0.01), 7);  // clamped
  EXPECT_EQ(levels.predictLevel(2.0, 3, 100.0), 0);
}

TEST(ScaleLevels, RejectsBadParameters) {
  EXPECT_THROW(ScaleLevels(0, 1.2), std::invalid_argument);
  EXPECT_THROW(ScaleLevels(8, 1.0), std::invalid_argument);
  EXPECT_THROW(ScaleLevels(8, std::nan("")), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
