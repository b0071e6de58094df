#include "eval/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "eval/eval_error.h"

namespace edgeslam {
namespace {

TEST(Statistics, KnownValuesOddCount) {
  const ErrorStatistics s = computeStatistics({3.0, 1.0, 2.0, 4.0, 10.0});
  EXPECT_EQ(s.count, 5U);
  EXPECT_DOUBLE_EQ(s.mean, 4.0);
  EXPECT_DOUBLE_EQ(s.median, 3.0);
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 10.0);
  EXPECT_DOUBLE_EQ(s.rmse, std::sqrt((9.0 + 1.0 + 4.0 + 16.0 + 100.0) / 5.0));
  // Population standard deviation (divides by n, as numpy.std).
  EXPECT_DOUBLE_EQ(s.std, std::sqrt((1.0 + 9.0 + 4.0 + 0.0 + 36.0) / 5.0));
}

TEST(Statistics, MedianOfEvenCountIsMeanOfMiddlePair) {
  EXPECT_DOUBLE_EQ(computeStatistics({4.0, 1.0, 3.0, 2.0}).median, 2.5);
}

TEST(Statistics, EmptyThrows) {
  EXPECT_THROW(computeStatistics({}), EvalError);
}

}  // namespace
}  // namespace edgeslam
