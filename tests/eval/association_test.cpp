#include "eval/association.h"

#include <gtest/gtest.h>

#include "eval/eval_error.h"

namespace edgeslam {
namespace {

Trajectory stamped(const std::vector<double>& times) {
  Trajectory t;
  for (std::size_t i = 0; i < times.size(); ++i) {
    t.push_back({times[i], SE3d(Eigen::Quaterniond::Identity(),
                                Eigen::Vector3d(static_cast<double>(i), 0, 0))});
  }
  return t;
}

TEST(AssociateByTimestamp, TakesClosestPairsFirstAndUsesEachPoseOnce) {
  // gt 1.00 is closest to est 1.004 (0.004); est 1.012 then has only gt 1.02 left (0.008).
  const Trajectory gt = stamped({1.00, 1.02, 2.0});
  const Trajectory est = stamped({1.012, 1.004, 5.0});
  const PosePairs pairs = associateByTimestamp(gt, est, 0.02);
  ASSERT_EQ(pairs.size(), 2U);
  EXPECT_DOUBLE_EQ(pairs[0].gt_timestamp, 1.00);
  EXPECT_DOUBLE_EQ(pairs[0].est_timestamp, 1.004);
  EXPECT_EQ(pairs[0].est_index, 1U);
  EXPECT_DOUBLE_EQ(pairs[1].gt_timestamp, 1.02);
  EXPECT_DOUBLE_EQ(pairs[1].est_timestamp, 1.012);
  EXPECT_DOUBLE_EQ(pairs[1].gt.translation().x(), 1.0);
  EXPECT_DOUBLE_EQ(pairs[1].est.translation().x(), 0.0);
}

TEST(AssociateByTimestamp, GreedyIsNotNearestNeighbour) {
  // est 0.5 is nearest to gt 0.51, but gt 0.51 is even nearer to est 0.515, which takes it first.
  const PosePairs pairs = associateByTimestamp(stamped({0.49, 0.51}), stamped({0.5, 0.515}), 0.02);
  ASSERT_EQ(pairs.size(), 2U);
  EXPECT_DOUBLE_EQ(pairs[0].est_timestamp, 0.5);
  EXPECT_DOUBLE_EQ(pairs[0].gt_timestamp, 0.49);
  EXPECT_DOUBLE_EQ(pairs[1].est_timestamp, 0.515);
}

TEST(AssociateByTimestamp, LimitIsStrictAndResultSortedByTime) {
  const PosePairs pairs =
      associateByTimestamp(stamped({3.0, 1.0, 2.0}), stamped({2.25, 1.125, 3.5, 2.875}), 0.25);
  ASSERT_EQ(pairs.size(), 2U);  // gt 2.0 / est 2.25 are exactly 0.25 apart: not < 0.25
  EXPECT_DOUBLE_EQ(pairs[0].gt_timestamp, 1.0);
  EXPECT_DOUBLE_EQ(pairs[1].gt_timestamp, 3.0);
  EXPECT_DOUBLE_EQ(pairs[1].est_timestamp, 2.875);
}

TEST(AssociateByTimestamp, NothingWithinLimitGivesEmpty) {
  EXPECT_TRUE(associateByTimestamp(stamped({0, 1}), stamped({10, 11}), 0.02).empty());
}

TEST(AssociateByTimestamp, RejectsNonPositiveLimit) {
  EXPECT_THROW(associateByTimestamp(stamped({0}), stamped({0}), 0.0), EvalError);
}

TEST(AssociateByIndex, PairsSamePositionAndRejectsDifferentLengths) {
  const PosePairs pairs = associateByIndex(stamped({0, 1, 2}), stamped({5, 6, 7}));
  ASSERT_EQ(pairs.size(), 3U);
  EXPECT_EQ(pairs[2].gt_index, 2U);
  EXPECT_DOUBLE_EQ(pairs[2].est_timestamp, 7.0);
  EXPECT_THROW(associateByIndex(stamped({0, 1}), stamped({0})), EvalError);
}

}  // namespace
}  // namespace edgeslam
