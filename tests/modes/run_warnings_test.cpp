// What a run that ended worse than it could says (issue 24, item 6).
#include "modes/run_warnings.h"

#include <gtest/gtest.h>

namespace edgeslam {
namespace {

TEST(RunWarnings, NameWhatMadeTheRunWorse) {
  RunHealth health{.frames = 400, .tracked = 340, .lost = 50};
  health.frames_dropped_late = 10;
  health.backend_busy_refusals = 100;
  health.backend_wait_ms = 30'000.0;
  health.wall_ms = 40'000.0;
  health.monocular = true;
  health.keyframe_depth_ratio = 0.3;
  const auto warnings = runWarnings(health);
  ASSERT_EQ(warnings.size(), 5u);
  EXPECT_NE(warnings[0].find("10 of 400 frames skipped late"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("lost on 50 of 390"), std::string::npos) << warnings[1];
  EXPECT_NE(warnings[2].find("backlog"), std::string::npos) << warnings[2];
  EXPECT_NE(warnings[3].find("waited 30.0 s"), std::string::npos) << warnings[3];
  EXPECT_NE(warnings[4].find("scale drift"), std::string::npos) << warnings[4];
}

TEST(RunWarnings, SayWhenAMapStartedAfterALossWasNeverMergedBack) {
  RunHealth health{.frames = 826, .tracked = 734, .lost = 70};
  health.maps_unmerged = 1;
  const auto warnings = runWarnings(health);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("1 map(s) started after tracking was lost"), std::string::npos)
      << warnings[0];
}

TEST(RunWarnings, NoneForAHealthyRun) {
  const RunHealth health{.frames = 400,
                         .tracked = 398,
                         .lost = 2,
                         .backend_busy_refusals = 3,
                         .backend_wait_ms = 5'000.0,
                         .wall_ms = 40'000.0,
                         .monocular = true,
                         .keyframe_depth_ratio = 1.3};
  EXPECT_TRUE(runWarnings(health).empty());
}

TEST(RunWarnings, SayWhyThereWasNoMapAndWhichFramesWereSkipped) {
  RunHealth never{.frames = 40, .tracked = 0, .lost = 0};
  never.map_built = false;
  never.frames_without_map = 40;
  never.refusals = "low_parallax 39";
  const auto none = runWarnings(never);
  ASSERT_EQ(none.size(), 1u);
  EXPECT_NE(none[0].find("no map was built in 40 frames"), std::string::npos) << none[0];
  EXPECT_NE(none[0].find("low_parallax 39"), std::string::npos) << none[0];

  RunHealth late{.frames = 100, .tracked = 60, .lost = 0};
  late.frames_without_map = 35;
  late.frames_out_of_order = 5;
  late.refusals = "too_few_features 30";
  const auto warnings = runWarnings(late);
  ASSERT_EQ(warnings.size(), 2u);
  EXPECT_NE(warnings[0].find("5 of 100 frames skipped"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("no map on 35 of 95 frames"), std::string::npos) << warnings[1];
}

}  // namespace
}  // namespace edgeslam
