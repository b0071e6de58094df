// The split as a user runs it: `run --mode edge|offload` embeds an edge server on loopback and the
// client talks gRPC to it; `server` + `client` do the same as two processes.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>

#include "support/edgeslam_command.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

nlohmann::json runMode(const std::string& mode, const std::string& extra, int frames) {
  const auto out = std::filesystem::temp_directory_path() / ("edgeslam_mode_test_" + mode);
  std::filesystem::remove_all(out);
  const auto r = test::runEdgeslam("run --dataset " + test::sharedPath(kSequence).string() +
                                   " --mode " + mode + " --max-frames " + std::to_string(frames) +
                                   " --vocab none --out " + out.string() + " " + extra);
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(out / "metrics.json");
  if (!in) return {};
  return nlohmann::json::parse(in);
}

TEST(EdgeModeCommand, RgbdEdgeModeSendsKeyframesAndAppliesEverySlice) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto m = runMode("edge", "--sensor rgbd", 90);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m["mode"], "edge");
  EXPECT_GE(m["tracked"].get<int>(), 89);
  EXPECT_GE(m["keyframes_uploaded"].get<int>(), 3);
  EXPECT_EQ(m["slices_applied"], m["keyframes_uploaded"]);
  EXPECT_GT(m["uplink_bytes"].get<double>(), 0.0);
  EXPECT_GT(m["downlink_bytes"].get<double>(), 0.0);
  EXPECT_GT(m["slice_latency_ms"]["median"].get<double>(), 0.0);
  EXPECT_LT(m["ate_final"]["rmse_m"].get<double>(), 0.05);
}

TEST(EdgeModeCommand, BoundedClientMapHoldsAPartOfTheEdgeMap) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto m = runMode("edge", "--sensor rgbd --client-map-keyframes 3", 150);
  ASSERT_FALSE(m.empty());
  EXPECT_GE(m["tracked"].get<int>(), 145);
  const auto& c = m["client_map"];
  ASSERT_TRUE(c.is_object()) << m.dump();
  EXPECT_EQ(c["window_keyframes"], 3);
  EXPECT_GT(c["keyframes_evicted"].get<int>(), 0);
  // Keep window ceil(1.5 * 3) = 5, plus keyframes made since the last slice.
  EXPECT_LE(c["keyframes"].get<int>(), 7);
  EXPECT_LT(c["keyframes"].get<int>(), m["keyframes"].get<int>());
  EXPECT_LT(c["points"].get<int>(), m["map_points"].get<int>());
  EXPECT_GE(c["max_points"].get<int>(), c["points"].get<int>());
  EXPECT_LT(m["ate_final"]["rmse_m"].get<double>(), 0.05);
}

TEST(EdgeModeCommand, OffloadModeTracksOnTheEdge) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto m = runMode("offload", "--sensor rgbd", 40);
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m["mode"], "offload");
  EXPECT_GE(m["tracked"].get<int>(), 39);
  // Every frame goes up as an image: far more than a few keyframes would cost.
  EXPECT_GT(m["uplink_bytes"].get<double>(), 40 * 20000.0);
  EXPECT_LT(m["ate"]["rmse_m"].get<double>(), 0.05);
}

TEST(EdgeModeCommand, ClientAgainstASeparateServerProcess) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const int port = 47000 + static_cast<int>(::getpid() % 1000);
  const std::string server_cmd = test::edgeslamBinary().string() +
                                 " server --listen 127.0.0.1:" + std::to_string(port) +
                                 " --status-every 0 > /dev/null 2>&1 & echo $!";
  FILE* pipe = ::popen(server_cmd.c_str(), "r");
  ASSERT_NE(pipe, nullptr);
  int server_pid = 0;
  ASSERT_EQ(std::fscanf(pipe, "%d", &server_pid), 1);
  ::pclose(pipe);
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  const auto out = std::filesystem::temp_directory_path() / "edgeslam_mode_test_client";
  std::filesystem::remove_all(out);
  const auto r =
      test::runEdgeslam("client --server 127.0.0.1:" + std::to_string(port) + " --dataset " +
                        test::sharedPath(kSequence).string() +
                        " --sensor rgbd --max-frames 40 --vocab none --out " + out.string());
  ::kill(server_pid, SIGTERM);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(out / "metrics.json");
  const auto m = nlohmann::json::parse(in);
  EXPECT_EQ(m["tracked"], 40);
  EXPECT_EQ(m["slices_applied"], m["keyframes_uploaded"]);
}

TEST(EdgeModeCommand, EdgeClientsExtractAtMost1600FeaturesUnlessAsked) {
  EDGESLAM_REQUIRE_SHARED("datasets/kitti07-160");
  const std::string common = "run --dataset " + test::sharedPath("datasets/kitti07-160").string() +
                             " --sensor mono --max-frames 3 --vocab none --mode ";
  // KITTI's wide images take 2000 features locally; an edge client's uploads stay near 60 KB.
  const auto local = test::runEdgeslam(common + "local");
  EXPECT_EQ(local.exit_code, 0) << local.output;
  EXPECT_NE(local.output.find("2000 ORB features"), std::string::npos) << local.output;
  const auto edge = test::runEdgeslam(common + "edge");
  EXPECT_EQ(edge.exit_code, 0) << edge.output;
  EXPECT_NE(edge.output.find("1600 ORB features"), std::string::npos) << edge.output;
  const auto asked = test::runEdgeslam(common + "edge --features 1900");
  EXPECT_EQ(asked.exit_code, 0) << asked.output;
  EXPECT_NE(asked.output.find("1900 ORB features"), std::string::npos) << asked.output;
}

TEST(EdgeModeCommand, ClientWithoutServerIsAClearError) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto r = test::runEdgeslam("client --server 127.0.0.1:1 --dataset " +
                                   test::sharedPath(kSequence).string() + " --max-frames 5");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("127.0.0.1:1"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace edgeslam
