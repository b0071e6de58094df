// What a run that ended worse than it could says (issue 24, item 6).
#include "pipeline/run_warnings.h"

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
  EXPECT_NE(warnings[0].find("10 of 400 frames dropped"), std::string::npos) << warnings[0];
  EXPECT_NE(warnings[1].find("lost on 50 of 390"), std::string::npos) << warnings[1];
  EXPECT_NE(warnings[2].find("backlog"), std::string::npos) << warnings[2];
  EXPECT_NE(warnings[3].find("waited 30.0 s"), std::string::npos) << warnings[3];
  EXPECT_NE(warnings[4].find("scale drift"), std::string::npos) << warnings[4];
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

}  // namespace
}  // namespace edgeslam
