// Temporal consistency of loop candidates on synthetic covisibility groups.
#include "mapping/loop_consistency.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace edgeslam {
namespace {

using Ids = std::vector<std::uint64_t>;

LoopCandidateGroup group(std::uint64_t candidate, Ids members) {
  return {candidate, std::move(members)};
}

TEST(LoopConsistency, AcceptsAfterThreeConsistentKeyFramesInARow) {
  LoopConsistency consistency(3);
  // The same place seen from four keyframes in a row, through overlapping groups.
  EXPECT_TRUE(consistency.update({group(10, {11, 12})}).empty());
  EXPECT_TRUE(consistency.update({group(12, {13, 14})}).empty());
  EXPECT_TRUE(consistency.update({group(14, {15})}).empty());
  EXPECT_EQ(consistency.update({group(15, {16})}), Ids{15});
  ASSERT_EQ(consistency.groups().size(), 1u);
  EXPECT_EQ(consistency.groups()[0].count, 3);
}

TEST(LoopConsistency, AGapResetsTheCount) {
  LoopConsistency consistency(3);
  consistency.update({group(10, {11})});
  consistency.update({group(11, {12})});
  consistency.update({});  // one keyframe without candidates breaks the chain
  consistency.update({group(12, {13})});
  consistency.update({group(13, {14})});
  EXPECT_TRUE(consistency.update({group(14, {15})}).empty());
  EXPECT_EQ(consistency.update({group(15, {16})}), Ids{15});
}

TEST(LoopConsistency, DisjointGroupsNeverAccumulate) {
  LoopConsistency consistency(3);
  for (std::uint64_t k = 0; k < 10; ++k) {
    // Candidates jump around the map: no two consecutive groups share a keyframe.
    EXPECT_TRUE(consistency.update({group(100 * k, {100 * k + 1, 100 * k + 2})}).empty());
    ASSERT_EQ(consistency.groups().size(), 1u);
    EXPECT_EQ(consistency.groups()[0].count, 0);
  }
}

TEST(LoopConsistency, OnlyTheConsistentCandidateOfSeveralIsAccepted) {
  LoopConsistency consistency(2);
  consistency.update({group(1, {2}), group(50, {51})});
  consistency.update({group(2, {3}), group(70, {71})});
  const Ids accepted = consistency.update({group(3, {4}), group(90, {91})});
  EXPECT_EQ(accepted, Ids{3});
}

TEST(LoopConsistency, APreviousGroupContinuesIntoOneNewGroupOnly) {
  LoopConsistency consistency(1);
  consistency.update({group(1, {2, 3})});
  // Both new groups touch the old one: both are consistent (and accepted), but only the first
  // carries the history on.
  const Ids accepted = consistency.update({group(2, {20}), group(3, {30})});
  EXPECT_EQ(accepted, (Ids{2, 3}));
  ASSERT_EQ(consistency.groups().size(), 1u);
  EXPECT_EQ(consistency.groups()[0].members, (Ids{2, 20}));
}

TEST(LoopConsistency, ResetForgetsHistory) {
  LoopConsistency consistency(1);
  consistency.update({group(1, {2})});
  consistency.reset();
  EXPECT_TRUE(consistency.update({group(2, {3})}).empty());
}

TEST(LoopConsistency, RejectsNegativeRequirement) {
  EXPECT_THROW(LoopConsistency(-1), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
