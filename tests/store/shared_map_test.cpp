// Two clients mapping one map at once, as a user meets it (issue "Map service II"): a real edge
// server with a store, two real clients (RGB-D, then monocular) playing redkitchen frames 0-549
// and 450-999 into `--map kitchen` at the same time. The second client starts where the map has
// nothing of its own yet: it maps in a part of its own, and a loop between the two parts merges
// them. The stored map then holds both clients' keyframes in one frame: its keyframe ATE, with one
// alignment for all of them (SE(3), Sim(3) for monocular), is compared with a single client's over
// the whole sequence into its own map; neither client may lose a frame.
// The server's edge view is watched meanwhile: one map with both clients' trajectories, the merge
// drawn and told as an event.
#include <gtest/gtest.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "io/trajectory.h"
#include "support/child_process.h"
#include "support/edgeslam_command.h"
#include "support/fresh_temp_dir.h"
#include "support/shared_data.h"
#include "support/small_vocabulary.h"
// clang-format off: after every header that includes Eigen, whose headers httplib's macros break.
#include <httplib.h>
// clang-format on

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";
constexpr auto kServerReady = std::chrono::seconds(60);
constexpr auto kClientRun = std::chrono::minutes(10);

std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string word; in >> word;) out.push_back(word);
  return out;
}

// The clients' ground truth together (each run writes its frames'), one line per timestamp.
void writeJointGroundTruth(const std::vector<std::filesystem::path>& runs,
                           const std::filesystem::path& file) {
  std::map<double, StampedPose> joint;
  for (const auto& run : runs) {
    for (const StampedPose& pose : readTumTrajectory(run / "groundtruth.tum")) {
      joint.emplace(pose.timestamp, pose);
    }
  }
  std::vector<StampedPose> poses;
  for (const auto& [t, pose] : joint) poses.push_back(pose);
  writeTumTrajectory(file, poses);
}

struct StoredMapFigures {
  std::size_t keyframes = 0;
  std::size_t keyframes_first_only = 0;   // frames only the first client played (< 450)
  std::size_t keyframes_second_only = 0;  // frames only the second client played (> 549)
  double ate_m = -1.0;
};

StoredMapFigures storedMap(const std::filesystem::path& store, const std::string& map,
                           const std::filesystem::path& ground_truth,
                           const std::filesystem::path& work, const std::string& align) {
  StoredMapFigures figures;
  const auto keyframes = work / (map + "_keyframes.tum");
  const auto exported = test::runEdgeslam("map export " + map + " --format tum --out " +
                                          keyframes.string() + " --maps " + store.string());
  EXPECT_EQ(exported.exit_code, 0) << exported.output;
  for (const StampedPose& pose : readTumTrajectory(keyframes)) {
    ++figures.keyframes;
    const double frame = pose.timestamp * 30.0;  // 7-Scenes frames are 1/30 s apart
    if (frame < 449.5) ++figures.keyframes_first_only;
    if (frame > 549.5) ++figures.keyframes_second_only;
  }
  const auto ate = test::runEdgeslam("eval ate --gt " + ground_truth.string() + " --est " +
                                         keyframes.string() + " --align " + align + " --json",
                                     false);
  const auto json = nlohmann::json::parse(ate.output, nullptr, false);
  if (json.is_object() && json.contains("rmse_m")) figures.ate_m = json["rmse_m"].get<double>();
  return figures;
}

// What the edge view showed of map `map` while it was live.
struct EdgeViewSeen {
  std::size_t snapshots = 0;
  std::size_t most_trajectories = 0;  // clients' keyframes in the map at once
  std::size_t sessions_in_map = 0;
  bool merge_drawn = false;  // a loop of the map marked as a merge
  std::string events;        // the latest event list, one per line
};

void look(httplib::Client& viewer, const std::string& map, EdgeViewSeen& seen) {
  const auto response = viewer.Get("/api/state");
  if (!response || response->status != 200) return;
  const auto snapshot = nlohmann::json::parse(response->body, nullptr, false);
  if (!snapshot.is_object()) return;
  ++seen.snapshots;
  for (const auto& m : snapshot.value("maps", nlohmann::json::array())) {
    if (m.value("name", "") != map || !m.value("live", false)) continue;
    seen.most_trajectories = std::max(seen.most_trajectories, m["trajectories"].size());
    seen.sessions_in_map = std::max(seen.sessions_in_map, m["sessions"].size());
    for (const auto& loop : m["loops"]) seen.merge_drawn |= loop.value("merge", false);
  }
  seen.events.clear();
  for (const auto& e : snapshot.value("events", nlohmann::json::array())) {
    seen.events += e.value("text", "") + "\n";
  }
}

// RGB-D: the parts meet by SE(3). Monocular: each part has a scale of its own, met by Sim(3).
class SharedMap : public ::testing::TestWithParam<std::string> {};

TEST_P(SharedMap, TwoClientsMappingOneMapAtOnceEndInOneFrame) {
  const std::string sensor = GetParam();
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto work = test::freshTempDir("shared_map_" + sensor);
  const auto store = work / "store";
  const auto logs = work / "logs";
  std::filesystem::create_directories(logs);
  const std::string vocab =
      " --vocab " + test::writeSmallVocabulary(test::freshTempDir("shared_map_vocab_" + sensor));
  const std::string dataset = " --dataset " + test::sharedPath(kSequence).string();
  const int port = 47900 + static_cast<int>(::getpid() % 90) + (sensor == "mono" ? 90 : 0);
  const std::string address = "127.0.0.1:" + std::to_string(port);
  test::ChildProcess server(test::edgeslamBinary(),
                            words("server --listen " + address + " --status-every 0" + vocab +
                                  " --semantic off --viewer 0 --maps " + store.string()),
                            logs / "server.log");
  ASSERT_TRUE(server.waitForLog("listening", kServerReady)) << server.log();
  std::smatch viewer_url;
  const std::string startup_log = server.log();
  ASSERT_TRUE(
      std::regex_search(startup_log, viewer_url, std::regex(R"(viewer: http://[\d.]+:(\d+)/)")))
      << startup_log;
  httplib::Client viewer("127.0.0.1", std::stoi(viewer_url[1]));
  viewer.set_read_timeout(std::chrono::seconds(10));

  const auto client = [&](const std::string& name, const std::string& frames,
                          const std::string& map) {
    return std::make_unique<test::ChildProcess>(
        test::edgeslamBinary(),
        words("client --server " + address + dataset + " --frames " + frames + " --sensor " +
              sensor + " --map " + map + vocab + " --out " + (work / name).string()),
        logs / (name + ".log"));
  };
  // The two halves at once, into one map.
  auto first = client("first", "0-549", "kitchen");
  auto second = client("second", "450-999", "kitchen");
  EdgeViewSeen seen;
  const auto deadline = std::chrono::steady_clock::now() + kClientRun;
  while ((first->running() || second->running()) && std::chrono::steady_clock::now() < deadline) {
    look(viewer, "kitchen", seen);
    std::this_thread::sleep_for(std::chrono::seconds(1));
  }
  EXPECT_EQ(first->wait(kClientRun), 0) << first->log();
  EXPECT_EQ(second->wait(kClientRun), 0) << second->log();
  // The client whose part moved goes on in the merged frame: no frame lost to the move (its last
  // keyframe, culled as a revisit of the other part, once left it at its pre-merge pose).
  for (const std::string name : {"first", "second"}) {
    std::ifstream metrics_file(work / name / "metrics.json");
    const auto metrics = nlohmann::json::parse(metrics_file, nullptr, false);
    ASSERT_TRUE(metrics.is_object()) << name;
    std::printf("%s client: %d frames lost, %d relocalisations\n", name.c_str(),
                metrics.value("lost", -1), metrics.value("relocalizations", -1));
    EXPECT_EQ(metrics.value("lost", -1), 0) << name << "\n" << server.log();
  }
  // One client over the whole sequence into a map of its own: the accuracy to match.
  auto whole = client("whole", "0-999", "whole");
  EXPECT_EQ(whole->wait(kClientRun), 0) << whole->log();
  server.signal(SIGTERM);
  EXPECT_EQ(server.wait(std::chrono::seconds(60)), 0) << server.log();
  const std::string server_log = server.log();

  // The second client joined the first's map, and a loop merged their parts.
  EXPECT_NE(server_log.find("joins map 'kitchen'"), std::string::npos) << server_log;
  EXPECT_NE(server_log.find("maps merged"), std::string::npos) << server_log;

  // The edge view showed one map with both clients in it, and the merge.
  std::printf("edge view: %zu snapshots, up to %zu trajectories in the map, merge drawn: %d\n",
              seen.snapshots, seen.most_trajectories, seen.merge_drawn ? 1 : 0);
  EXPECT_GE(seen.most_trajectories, 2u) << seen.snapshots << " snapshots";
  EXPECT_EQ(seen.sessions_in_map, 2u);
  EXPECT_TRUE(seen.merge_drawn);
  EXPECT_NE(seen.events.find("maps merged in 'kitchen'"), std::string::npos) << seen.events;

  // Each client's session is recorded with the map.
  const auto info = test::runEdgeslam("map info kitchen --json --maps " + store.string());
  const auto info_json = nlohmann::json::parse(info.output, nullptr, false);
  ASSERT_TRUE(info_json.is_object()) << info.output;
  EXPECT_EQ(info_json.value("sessions", 0), 2) << info.output;

  writeJointGroundTruth({work / "first", work / "second"}, work / "halves_truth.tum");
  const std::string align = sensor == "mono" ? "sim3" : "se3";
  const StoredMapFigures shared =
      storedMap(store, "kitchen", work / "halves_truth.tum", work, align);
  const StoredMapFigures single =
      storedMap(store, "whole", work / "whole" / "groundtruth.tum", work, align);
  std::printf(
      "shared map: %zu keyframes (%zu of frames only the first client played, %zu only the "
      "second's), keyframe ATE %.2f cm; single client: %zu keyframes, %.2f cm (ratio %.2f)\n",
      shared.keyframes, shared.keyframes_first_only, shared.keyframes_second_only,
      shared.ate_m * 100, single.keyframes, single.ate_m * 100, shared.ate_m / single.ate_m);
  EXPECT_GE(shared.keyframes_first_only, 10u);
  EXPECT_GE(shared.keyframes_second_only, 10u);
  ASSERT_GT(single.ate_m, 0.0);
  ASSERT_GT(shared.ate_m, 0.0);
  // Both halves in one frame: one alignment fits them as well as it fits one client's map (the
  // issue's bound is 20 %; a map left in two frames is off by tens of centimetres).
  EXPECT_LT(shared.ate_m, 1.2 * single.ate_m + 0.005);
  std::filesystem::remove_all(work);
}

INSTANTIATE_TEST_SUITE_P(Sensors, SharedMap, ::testing::Values("rgbd", "mono"),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace edgeslam
