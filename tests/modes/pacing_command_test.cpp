// Offline pacing (issue 24): frames fed back to back (`--fast`, the default) must build the map a
// camera-paced run builds, and say how long tracking waited for the back end; a run that ended
// worse than it could says so; `--deterministic` runs are identical.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

std::string readFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::filesystem::path freshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("edgeslam_pacing_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

nlohmann::json readMetrics(const std::filesystem::path& out) {
  std::ifstream in(out / "metrics.json");
  return nlohmann::json::parse(in);
}

struct KittiRun {
  int exit_code = 0;
  std::string output;
  nlohmann::json metrics;  // when it exited 0
};

// A monocular `run` over KITTI 03's first 400 frames with `args` (mode, pacing, store).
KittiRun runOnKitti03(const std::string& name, const std::string& args) {
  const auto out = freshDir(name);
  const auto r =
      test::runEdgeslam("run --dataset " + test::sharedPath("datasets/kitti03-400").string() +
                        " --sensor mono " + args + " --out " + out.string());
  KittiRun run{r.exit_code, r.output, {}};
  if (r.exit_code == 0) run.metrics = readMetrics(out);
  return run;
}

// KITTI 03's first 400 frames, monocular, local mode: before the back end set the pace, a mapper
// that fell behind let the map's scale shrink along the drive (issue 24: ATE 2.92 m fed back to
// back against 0.71 m paced at the camera's rate).
TEST(Pacing, FastLocalMonocularRunOnKittiKeepsTheCameraPacedAccuracy) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti03-400");
  const KittiRun run = runOnKitti03("kitti03_fast", "--mode local --fast");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto& metrics = run.metrics;
  EXPECT_EQ(metrics["pacing"], "fast");
  EXPECT_GE(metrics["tracked"].get<int>(), 390);
  // With the wait: 0.83 and 0.99 m on a saturated host (docs/benchmarks.md, Pacing).
  EXPECT_LT(metrics["ate_final"]["rmse_m"].get<double>(), 1.3);
  // Tracking outran the mapper on this machine and waited for it, and says how long.
  EXPECT_GT(metrics["backend_waits"].get<int>(), 0);
  for (const char* stat : {"total", "median", "p90", "p99", "max"}) {
    ASSERT_TRUE(metrics["backend_wait_ms"].contains(stat)) << stat;
  }
  EXPECT_GT(metrics["backend_wait_ms"]["total"].get<double>(), 0.0);
  EXPECT_GE(metrics["backend_wait_ms"]["max"].get<double>(),
            metrics["backend_wait_ms"]["median"].get<double>());
  EXPECT_EQ(metrics["frames_dropped_late"], 0);
  ASSERT_TRUE(metrics["warnings"].is_array());
  for (const auto& warning : metrics["warnings"]) {
    EXPECT_EQ(warning.get<std::string>().find("scale drift"), std::string::npos) << warning;
  }
}

// The same drive in edge mode at the camera's pace, the edge in-process over loopback gRPC.
// Table I's link probes once read a loopback link as a slow one (an edge busy with the new map's
// first keyframes answered the first sized probe late, and only late answers were kept): the last
// row's 4 pyramid levels for the rest of the drive, tracking lost at frame ~100-290 and never
// regained, in 2 of 3 runs.
TEST(Pacing, RealtimeEdgeMonocularRunOnKittiTracksTheDrive) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti03-400");
  const KittiRun run = runOnKitti03("kitti03_edge_realtime", "--mode edge --realtime --maps none");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto& metrics = run.metrics;
  EXPECT_EQ(metrics["pacing"], "realtime");
  EXPECT_GE(metrics["tracked"].get<int>(), 380) << run.output;
  // 0.69-0.87 m over 285 m in 5 runs on a quiet host (ORB-SLAM's published monocular figure for
  // the whole of 03: 1.59 m over 561 m).
  EXPECT_LT(metrics["ate_final"]["rmse_m"].get<double>(), 1.3);
  // Loopback: most frames with the 6-8 pyramid levels of Table I's first three rows.
  const auto& per_config = metrics["adapt"]["frames_per_config"];
  ASSERT_EQ(per_config.size(), 5u);
  const double frames = metrics["frames_processed"].get<double>();
  const double last_rows = per_config[3].get<double>() + per_config[4].get<double>();
  EXPECT_LT(last_rows, 0.1 * frames) << metrics["adapt"].dump();
}

// Offload mode fed back to back: the client sends every frame and waits for its pose, so the
// edge's tracking outran its own mapper as local mode's once did. The session is told the frames
// come back to back (SessionSettings.frames_back_to_back) and its tracking waits for its back end
// before each keyframe; the waits come back with the poses and are counted in metrics.json.
TEST(Pacing, FastOffloadRunWaitsForTheEdgesBackEnd) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti03-400");
  const KittiRun run = runOnKitti03("kitti03_offload_fast", "--mode offload --fast --maps none");
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto& metrics = run.metrics;
  EXPECT_EQ(metrics["pacing"], "fast");
  EXPECT_GE(metrics["tracked"].get<int>(), 390) << run.output;
  // 0.818 [0.795-1.028] m fed back to back, 0.807 [0.795-0.975] at the camera's pace (3 runs
  // each, docs/benchmarks.md, Accuracy against pacing).
  EXPECT_LT(metrics["ate_final"]["rmse_m"].get<double>(), 1.3);
  EXPECT_GT(metrics["backend_waits"].get<int>(), 0);
  EXPECT_GT(metrics["backend_wait_ms"]["total"].get<double>(), 0.0);
  EXPECT_GE(metrics["backend_wait_ms"]["max"].get<double>(),
            metrics["backend_wait_ms"]["median"].get<double>());
}

// `--deterministic` (for tests and bisecting): the back end in lock-step with tracking, one
// thread, so two runs write the same trajectories byte for byte, monocular and RGB-D.
TEST(Pacing, DeterministicRunsAreIdentical) {
  EDGESLAM_REQUIRE_SHARED("datasets/7scenes-redkitchen-1000");
  const std::string dataset = test::sharedPath("datasets/7scenes-redkitchen-1000").string();
  for (const std::string sensor : {"mono", "rgbd"}) {
    std::string trajectories[2];
    std::string final_trajectories[2];
    for (int run = 0; run < 2; ++run) {
      const auto out = freshDir("deterministic_" + sensor + std::to_string(run));
      const auto r =
          test::runEdgeslam("run --dataset " + dataset + " --mode local --sensor " + sensor +
                            " --frames 0-199 --deterministic --maps none --out " + out.string());
      ASSERT_EQ(r.exit_code, 0) << r.output;
      const auto metrics = readMetrics(out);
      EXPECT_EQ(metrics["deterministic"], true);
      EXPECT_GE(metrics["tracked"].get<int>(), 150) << sensor;
      trajectories[run] = readFile(out / "trajectory.tum");
      final_trajectories[run] = readFile(out / "trajectory_final.tum");
      ASSERT_FALSE(trajectories[run].empty());
    }
    EXPECT_EQ(trajectories[0], trajectories[1]) << sensor;
    EXPECT_EQ(final_trajectories[0], final_trajectories[1]) << sensor;
  }
}

}  // namespace
}  // namespace edgeslam
