// `--realtime` plays a dataset as a live camera (issue 25): a client too slow for its camera
// takes the newest frame due, skips (and never reads) the ones it was busy for, and counts them;
// its latency stays bounded instead of growing with a queue of stale frames.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
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
  // At least every second frame goes: a read alone outlasts a period.
  EXPECT_GE(skipped, 150u) << r.output;
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
}

}  // namespace
}  // namespace edgeslam
