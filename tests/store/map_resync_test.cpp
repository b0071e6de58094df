// A server killed mid-run and restarted on the same store loses nothing (issue 19 item 3): the
// real binaries, two processes, redkitchen at frame rate. The restarted server resumes the stored
// map, the client reconnects, receives a full resync, and re-sends the keyframes the edge lacks.
// Compared with the same run undisturbed: edge keyframes, keyframe ATE, client frames.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>

#include "support/edgeslam_command.h"
#include "support/fresh_temp_dir.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

std::filesystem::path tempDir(const std::string& name) {
  return test::freshTempDir("map_resync_" + name);
}

int startInBackground(const std::string& arguments, const std::filesystem::path& log) {
  const std::string command =
      test::edgeslamBinary().string() + " " + arguments + " > " + log.string() + " 2>&1 & echo $!";
  FILE* pipe = ::popen(command.c_str(), "r");
  int pid = 0;
  if (pipe == nullptr || std::fscanf(pipe, "%d", &pid) != 1) pid = 0;
  if (pipe != nullptr) ::pclose(pipe);
  return pid;
}

nlohmann::json readJson(const std::filesystem::path& file) {
  std::ifstream in(file);
  return nlohmann::json::parse(in, nullptr, false);
}

struct RunFigures {
  nlohmann::json metrics;        // the client's metrics.json
  nlohmann::json map_info;       // `map info --json` of the store afterwards
  double keyframe_ate_m = -1.0;  // the stored edge map's keyframes against the ground truth
  std::string client_output;
};

// One client run against a server on `store`; with `kill_after`, the server is SIGKILLed that
// long after the client started and restarted on the same store two seconds later.
RunFigures runClient(const std::string& name, std::optional<std::chrono::milliseconds> kill_after) {
  const auto store = tempDir(name + "_store");
  const auto out = tempDir(name + "_out");
  const auto logs = tempDir(name + "_logs");
  std::filesystem::create_directories(logs);
  const int port = 46000 + static_cast<int>(::getpid() % 1000) + (kill_after ? 1 : 0);
  const std::string address = "127.0.0.1:" + std::to_string(port);
  const std::string serve = "server --listen " + address +
                            " --status-every 0 --vocab none --semantic off --maps " +
                            store.string();
  RunFigures figures;
  int server = startInBackground(serve, logs / "server1.log");
  EXPECT_GT(server, 0);
  std::this_thread::sleep_for(std::chrono::milliseconds(800));
  test::CommandResult client;
  std::thread client_thread([&] {
    client = test::runEdgeslam(
        "client --server " + address + " --dataset " + test::sharedPath(kSequence).string() +
        " --sensor rgbd --realtime --vocab none --map kitchen --out " + out.string());
  });
  if (kill_after) {
    std::this_thread::sleep_for(*kill_after);
    EXPECT_EQ(::kill(server, SIGKILL), 0);
    std::this_thread::sleep_for(std::chrono::seconds(2));
    server = startInBackground(serve, logs / "server2.log");
    EXPECT_GT(server, 0);
  }
  client_thread.join();
  ::kill(server, SIGTERM);
  std::this_thread::sleep_for(std::chrono::milliseconds(1500));  // the store's last batch
  figures.client_output = client.output;
  EXPECT_EQ(client.exit_code, 0) << client.output;
  figures.metrics = readJson(out / "metrics.json");
  const auto info = test::runEdgeslam("map info kitchen --json --maps " + store.string(), false);
  figures.map_info = nlohmann::json::parse(info.output, nullptr, false);
  const auto exported =
      test::runEdgeslam("map export kitchen --format tum --out " +
                        (out / "edge_keyframes.tum").string() + " --maps " + store.string());
  EXPECT_EQ(exported.exit_code, 0) << exported.output;
  const auto ate =
      test::runEdgeslam("eval ate --gt " + (out / "groundtruth.tum").string() + " --est " +
                            (out / "edge_keyframes.tum").string() + " --align se3 --json",
                        false);
  const auto ate_json = nlohmann::json::parse(ate.output, nullptr, false);
  if (ate_json.is_object() && ate_json.contains("rmse_m")) {
    figures.keyframe_ate_m = ate_json["rmse_m"].get<double>();
  }
  std::filesystem::remove_all(store);
  std::filesystem::remove_all(out);
  return figures;
}

TEST(MapResync, ServerKilledAndRestartedOnItsStoreLosesNoKeyframe) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const RunFigures calm = runClient("calm", std::nullopt);
  // ~40 % of the 1000 frames at 30 fps, after the client's start-up.
  const RunFigures killed = runClient("killed", std::chrono::milliseconds(14500));
  ASSERT_TRUE(calm.metrics.is_object());
  ASSERT_TRUE(killed.metrics.is_object()) << killed.client_output;
  ASSERT_TRUE(calm.map_info.is_object());
  ASSERT_TRUE(killed.map_info.is_object());
  const auto& m = killed.metrics;
  std::printf(
      "undisturbed: %d edge keyframes (store %d), keyframe ATE %.4f m, %d frames, %d tracked\n"
      "killed:      %d edge keyframes (store %d), keyframe ATE %.4f m, %d frames, %d tracked; "
      "resync %s\n",
      calm.metrics["keyframes"].get<int>(), calm.map_info["keyframes"].get<int>(),
      calm.keyframe_ate_m, calm.metrics["frames"].get<int>(), calm.metrics["tracked"].get<int>(),
      m["keyframes"].get<int>(), killed.map_info["keyframes"].get<int>(), killed.keyframe_ate_m,
      m["frames"].get<int>(), m["tracked"].get<int>(), m["resync"].dump().c_str());

  // The client saw the outage and was resynchronised.
  EXPECT_GE(m["resync"]["full_resyncs"].get<int>(), 1) << m["resync"].dump();
  // The restarted server resumed the stored session instead of starting an empty one.
  EXPECT_EQ(killed.map_info["sessions"], 1) << killed.map_info.dump();
  // No frame of the client lost.
  EXPECT_EQ(m["frames"], calm.metrics["frames"]);
  // Of the frames processed: a paced client skips the frames it is late for, as many as the
  // host's load makes it.
  const auto tracked_share = [](const nlohmann::json& metrics) {
    return metrics["tracked"].get<double>() / metrics["frames_processed"].get<double>();
  };
  EXPECT_GE(tracked_share(m), 0.95 * tracked_share(calm.metrics));
  // Every keyframe the client made is in the stored edge map, culled there as redundant (a
  // revisit), or counted as lost with a reason.
  ASSERT_TRUE(m["resync"]["keyframes_lost"].is_object());
  int lost = 0;
  for (const auto& [reason, count] : m["resync"]["keyframes_lost"].items())
    lost += count.get<int>();
  const double made = m["resync"]["keyframes_made"].get<double>();
  const double culled = m["resync"]["keyframes_culled_by_edge"].get<double>();
  EXPECT_GE(killed.map_info["keyframes"].get<double>() + culled + lost, 0.97 * made)
      << m["resync"].dump();
  // And not far from what an undisturbed run holds. The two runs decide their keyframes apart
  // (the live camera skips other frames; a resynchronised client tracks a denser map and makes
  // fewer): 70-108 measured against 88-99 undisturbed. The bug, the keyframes before the
  // outage lost, left about 40 %.
  const double calm_keyframes = calm.map_info["keyframes"].get<double>();
  EXPECT_GE(killed.map_info["keyframes"].get<double>(), 0.6 * calm_keyframes);
  // Keyframe accuracy: within 10 % of the undisturbed run's, or 1 cm (run-to-run spread).
  ASSERT_GT(calm.keyframe_ate_m, 0.0);
  ASSERT_GT(killed.keyframe_ate_m, 0.0);
  EXPECT_LE(killed.keyframe_ate_m, std::max(1.1 * calm.keyframe_ate_m, calm.keyframe_ate_m + 0.01));
}

}  // namespace
}  // namespace edgeslam
