// `--realtime` plays a dataset as a live camera (issue 25): a client too slow for its camera
// takes the newest frame due, skips (and never reads) the ones it was busy for, and counts them;
// its latency stays bounded instead of growing with a queue of stale frames.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <string>

#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

std::filesystem::path freshDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("edgeslam_live_camera_test_" + name);
  std::filesystem::remove_all(dir);
  return dir;
}

nlohmann::json readMetrics(const std::filesystem::path& out) {
  std::ifstream in(out / "metrics.json");
  return nlohmann::json::parse(in);
}

// Every read takes 60 ms (the test hook), 1.8 periods of the 30 fps camera: before, frames were
// read in order and handed over late, the latency growing by ~27 ms a frame (8 s after 300).
TEST(LiveCameraCommand, AStarvedRealtimeClientSkipsToTheNewestFrameAndStaysBounded) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto out = freshDir("starved");
  ASSERT_EQ(::setenv("EDGESLAM_TEST_EXTRA_LOAD_MS", "60", 1), 0);  // the binary inherits it
  const auto r = test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                                   " --mode local --sensor rgbd --realtime --max-frames 300"
                                   " --vocab none --out " +
                                   out.string());
  ::unsetenv("EDGESLAM_TEST_EXTRA_LOAD_MS");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto metrics = readMetrics(out);
  EXPECT_EQ(metrics["pacing"], "realtime");
  const auto skipped = metrics["frames_skipped_late"].get<std::size_t>();
  const auto processed = metrics["frames_processed"].get<std::size_t>();
  // A frame at most every 60 ms (a read, overlapped with tracking the previous frame) of a camera
  // making one every 33.3: at most 167 of the 300 are processed.
  EXPECT_GE(skipped, 130u) << r.output;
  EXPECT_EQ(skipped + processed + metrics["frames_out_of_order"]["skipped"].get<std::size_t>(),
            300u);
  EXPECT_EQ(metrics["frames_dropped_late"].get<std::size_t>(), skipped);
  // Skipped frames were not read, but for a frame read ahead in vain now and then.
  EXPECT_EQ(metrics["frames_read"].get<std::size_t>(),
            processed + metrics["frames_read_unused"].get<std::size_t>());
  EXPECT_LE(metrics["frames_read_unused"].get<std::size_t>(), processed / 10);
  // Bounded: one period of waiting, the 60 ms read and tracking, with room for a loaded host;
  // the in-order reader ended seconds behind.
  EXPECT_LT(metrics["e2e_ms"]["p95"].get<double>(), 400.0) << metrics["e2e_ms"].dump();
  // At ~13 fps the motion between frames more than doubles; tracking holds.
  EXPECT_GE(metrics["tracked"].get<double>(), 0.9 * static_cast<double>(processed));
  ASSERT_TRUE(metrics.contains("ate"));
  EXPECT_LT(metrics["ate"]["rmse_m"].get<double>(), 0.15);
  EXPECT_NE(r.output.find("skipped late"), std::string::npos) << r.output;
  // The client fitted its extraction to what it could do: frames were skipped in every window, so
  // the compute budget went down its ladder (600 of 1000 features, 5 of 8 levels) and said so.
  const auto& budget = metrics["compute_budget"];
  EXPECT_EQ(budget["deepest_step"].get<int>(), 3) << budget.dump();
  EXPECT_EQ(budget["least"]["features"].get<int>(), 600) << budget.dump();
  EXPECT_EQ(budget["least"]["levels"].get<int>(), 5) << budget.dump();
  EXPECT_GT(budget["frames_with_fewer_features"].get<std::size_t>(), processed / 2);
  EXPECT_NE(r.output.find("compute      fitted to the CPU"), std::string::npos) << r.output;
  std::ifstream frames(out / "frames.csv");
  std::string header;
  std::getline(frames, header);
  EXPECT_NE(header.find(",features,levels"), std::string::npos) << header;
}

TEST(LiveCameraCommand, WithComputeAdaptationOffAStarvedClientKeepsItsExtraction) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto out = freshDir("fixed");
  ASSERT_EQ(::setenv("EDGESLAM_TEST_EXTRA_LOAD_MS", "60", 1), 0);
  const auto r = test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                                   " --mode local --sensor mono --realtime --max-frames 90"
                                   " --vocab none --compute-adapt off --out " +
                                   out.string());
  ::unsetenv("EDGESLAM_TEST_EXTRA_LOAD_MS");
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const auto metrics = readMetrics(out);
  EXPECT_GE(metrics["frames_skipped_late"].get<std::size_t>(), 35u);  // of 90, as above
  EXPECT_FALSE(metrics.contains("compute_budget"));
  std::ifstream frames(out / "frames.csv");
  std::string line;
  std::getline(frames, line);
  std::size_t rows = 0;
  while (std::getline(frames, line)) {
    ++rows;
    EXPECT_TRUE(line.ends_with(",1000,8")) << line;
  }
  EXPECT_EQ(rows, metrics["frames_processed"].get<std::size_t>());
}

// Frames decoded into memory first are the same frames: a lock-step local run gives the same
// trajectory with --preload as without.
TEST(LiveCameraCommand, PreloadedFramesGiveTheSameTrajectory) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  std::string trajectories[2];
  for (int preload = 0; preload < 2; ++preload) {
    const auto out = freshDir(preload ? "preloaded" : "read");
    const auto r = test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                                     " --mode local --sensor rgbd --deterministic --max-frames 60"
                                     " --vocab none --refine-intrinsics off --out " +
                                     out.string() + (preload ? " --preload" : ""));
    ASSERT_EQ(r.exit_code, 0) << r.output;
    std::ifstream in(out / "trajectory.tum");
    trajectories[preload].assign(std::istreambuf_iterator<char>(in), {});
  }
  EXPECT_GT(trajectories[0].size(), 1000u);
  EXPECT_EQ(trajectories[0], trajectories[1]);
}

TEST(LiveCameraCommand, PreloadAndRepeatAreRefusedTogether) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto r =
      test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                        " --mode local --preload --repeat 2 --out " + freshDir("repeat").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("--preload"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace edgeslam
