#include "adapt/compute_budget.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace edgeslam {
namespace {

constexpr double kPeriodMs = 1000.0 / 30.0;

ComputeBudgetOptions thirtyFps() {
  ComputeBudgetOptions options;
  options.period_ms = kPeriodMs;
  options.window = 10;
  options.up_windows = 3;
  return options;
}

// Feeds `frames` frames of `ms` each, `skipped` skipped before each; returns the changes seen.
int feed(ComputeBudget& budget, int frames, double ms, std::size_t skipped = 0) {
  int changes = 0;
  for (int i = 0; i < frames; ++i) changes += budget.onFrame(ms, skipped) ? 1 : 0;
  return changes;
}

TEST(ComputeBudget, AClientWithinItsBudgetKeepsTheConfiguration) {
  ComputeBudget budget(thirtyFps());
  EXPECT_EQ(feed(budget, 300, 12.0), 0);
  EXPECT_EQ(budget.step(), 0u);
  EXPECT_EQ(budget.current(), computeSteps()[0]);
  EXPECT_EQ(budget.framesPerStep()[0], 300u);
}

TEST(ComputeBudget, ASlowClientStepsDownOncePerWindowToTheLastStepAndStaysThere) {
  ComputeBudget budget(thirtyFps());
  EXPECT_EQ(feed(budget, 9, 40.0), 0);  // not a whole window yet
  EXPECT_EQ(feed(budget, 1, 40.0), 1);
  EXPECT_EQ(budget.step(), 1u);
  feed(budget, 100, 40.0);
  EXPECT_EQ(budget.step(), kComputeSteps - 1);
  EXPECT_EQ(budget.switches(), kComputeSteps - 1);
  EXPECT_EQ(budget.deepestStep(), kComputeSteps - 1);
}

TEST(ComputeBudget, OneSlowFrameInAWindowMovesNothing) {
  ComputeBudget budget(thirtyFps());
  for (int window = 0; window < 20; ++window) {
    feed(budget, 9, 15.0);
    feed(budget, 1, 300.0);  // a keyframe, or the host took the core away
  }
  EXPECT_EQ(budget.step(), 0u);
}

TEST(ComputeBudget, SkippedFramesStepDownEvenWhenTrackingItselfFits) {
  // Reading the camera shares the client's CPU: frames can be missed while tracking takes 20 ms.
  ComputeBudget budget(thirtyFps());
  EXPECT_EQ(feed(budget, 10, 20.0, 1), 1);
  EXPECT_EQ(budget.step(), 1u);
}

TEST(ComputeBudget, StepsBackUpOnlyAfterSeveralWindowsWithRoom) {
  ComputeBudget budget(thirtyFps());
  feed(budget, 20, 40.0);
  ASSERT_EQ(budget.step(), 2u);
  EXPECT_EQ(feed(budget, 29, 10.0), 0);  // two windows with room, and most of a third
  EXPECT_EQ(feed(budget, 1, 10.0), 1);
  EXPECT_EQ(budget.step(), 1u);
  // A window in between that has no room starts the count again.
  feed(budget, 20, 10.0);
  feed(budget, 10, 20.0);
  feed(budget, 20, 10.0);
  EXPECT_EQ(budget.step(), 1u);
  feed(budget, 10, 10.0);
  EXPECT_EQ(budget.step(), 0u);
  EXPECT_EQ(budget.deepestStep(), 2u);
}

TEST(ComputeBudget, AWindowWithASkippedFrameIsNoRoomToStepUp) {
  ComputeBudget budget(thirtyFps());
  feed(budget, 10, 40.0);
  ASSERT_EQ(budget.step(), 1u);
  for (int window = 0; window < 10; ++window) {
    feed(budget, 9, 10.0);
    budget.onFrame(10.0, 1);  // below skipped_share, but not a window with room
  }
  EXPECT_EQ(budget.step(), 1u);
}

TEST(ComputeBudget, StepsKeepFewerFeaturesAndNeverMoreLevelsThanConfigured) {
  const auto& steps = computeSteps();
  for (std::size_t i = 1; i < steps.size(); ++i) {
    EXPECT_LT(steps[i].features(1000), steps[i - 1].features(1000));
    EXPECT_LE(steps[i].levels(8), steps[i - 1].levels(8));
  }
  EXPECT_EQ(steps[0].features(1000), 1000);
  EXPECT_EQ(steps[0].levels(8), 8);
  EXPECT_GE(steps.back().features(1000), 500);  // RGB-D initialisation still has its features
  EXPECT_EQ(steps.back().levels(4), 4);         // a cap, not a floor (Table I may ask for 4)
}

TEST(ComputeBudget, RejectsOptionsThatCannotWork) {
  ComputeBudgetOptions options = thirtyFps();
  options.period_ms = 0.0;
  EXPECT_THROW(ComputeBudget{options}, std::invalid_argument);
  options = thirtyFps();
  options.window = 0;
  EXPECT_THROW(ComputeBudget{options}, std::invalid_argument);
  options = thirtyFps();
  options.under_budget = 0.9;
  EXPECT_THROW(ComputeBudget{options}, std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
