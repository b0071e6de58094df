// Localisation in a map made earlier, as a user meets it: an edge run maps redkitchen (all 1000
// RGB-D frames) into a store; a second run localises frames 500-999 in that stored map with
// `--localize-only`, in local mode and as a client of a real edge server. The second run must find
// its first pose quickly, stay localised, report poses in the stored map's frame (compared with the
// mapping run's own poses without any alignment) and leave the store as it was, byte for byte.
// Along the way it follows a route made on the stored map (checkpoints every 0.5 m of the mapping
// run's keyframe path over the same frames), as in the paper's navigation study.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "io/trajectory.h"
#include "support/child_process.h"
#include "support/edgeslam_command.h"
#include "support/fresh_temp_dir.h"
#include "support/shared_data.h"
#include "support/small_vocabulary.h"

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

std::string fileBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

std::vector<std::string> words(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string word; in >> word;) out.push_back(word);
  return out;
}

nlohmann::json readMetrics(const std::filesystem::path& out) {
  std::ifstream in(out / "metrics.json");
  return nlohmann::json::parse(in);
}

// The stored map the tests localise in: an edge run over all 1000 RGB-D frames of redkitchen, and
// a route along its keyframe path over frames 500-999 (~1 min; ctest runs each test in a process
// of its own, so each makes it).
class LocalizeOnly : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!std::filesystem::exists(test::sharedPath(kSequence))) return;
    store_ = new std::filesystem::path(test::freshTempDir("localize_store"));
    mapping_out_ = new std::filesystem::path(test::freshTempDir("localize_mapping"));
    vocab_folder_ = new std::filesystem::path(test::freshTempDir("localize_vocab"));
    vocab_ = new std::string(" --vocab " + test::writeSmallVocabulary(*vocab_folder_));
    const auto mapping = test::runEdgeslam(
        "run --dataset " + dataset() + " --mode edge --sensor rgbd --maps " + store_->string() +
        " --map kitchen" + *vocab_ + " --out " + mapping_out_->string());
    ASSERT_EQ(mapping.exit_code, 0) << mapping.output;
    const auto route =
        test::runEdgeslam("route make walk --map kitchen --every 0.5 --frames 500-999 " +
                          std::string("--maps ") + store_->string());
    ASSERT_EQ(route.exit_code, 0) << route.output;
  }
  static void TearDownTestSuite() {
    for (const std::filesystem::path* folder : {store_, mapping_out_, vocab_folder_}) {
      if (folder != nullptr) std::filesystem::remove_all(*folder);
      delete folder;
    }
    delete vocab_;
  }
  void SetUp() override {
    EDGESLAM_REQUIRE_SHARED(kSequence);
    ASSERT_NE(store_, nullptr);
  }

  static std::string dataset() { return test::sharedPath(kSequence).string(); }

  // RMS distance of a localising run's poses (trajectory.tum, at frame time) from the mapping
  // run's final poses of the same frames, with no alignment; and how many frames were compared.
  static std::pair<double, std::size_t> distanceFromMappingRun(
      const std::filesystem::path& localize_out) {
    std::map<double, Eigen::Vector3d> mapped;
    for (const auto& p : readTumTrajectory(*mapping_out_ / "trajectory_final.tum")) {
      mapped[p.timestamp] = p.pose.translation();
    }
    double squared = 0.0;
    std::size_t pairs = 0;
    for (const auto& p : readTumTrajectory(localize_out / "trajectory.tum")) {
      const auto it = mapped.find(p.timestamp);
      if (it == mapped.end()) continue;
      squared += (p.pose.translation() - it->second).squaredNorm();
      ++pairs;
    }
    return {pairs == 0 ? 0.0 : std::sqrt(squared / static_cast<double>(pairs)), pairs};
  }

  static std::filesystem::path* store_;
  static std::filesystem::path* mapping_out_;
  static std::filesystem::path* vocab_folder_;
  static std::string* vocab_;
};

std::filesystem::path* LocalizeOnly::store_ = nullptr;
std::filesystem::path* LocalizeOnly::mapping_out_ = nullptr;
std::filesystem::path* LocalizeOnly::vocab_folder_ = nullptr;
std::string* LocalizeOnly::vocab_ = nullptr;

TEST_F(LocalizeOnly, FramesOfTheSecondHalfLocaliseInTheStoredMapAndFollowARouteOnIt) {
  const auto localize_out = test::freshTempDir("localize_run");
  const std::string store_before = fileBytes(*store_ / "maps.sqlite");
  ASSERT_FALSE(store_before.empty());

  const auto localize =
      test::runEdgeslam("run --dataset " + dataset() +
                        " --frames 500-999 --mode local --sensor rgbd --localize-only" +
                        " --maps " + store_->string() + " --map kitchen --route walk" + *vocab_ +
                        " --out " + localize_out.string());
  ASSERT_EQ(localize.exit_code, 0) << localize.output;
  const auto metrics = readMetrics(localize_out);
  SCOPED_TRACE(metrics.dump());
  EXPECT_TRUE(metrics["localize_only"].get<bool>());
  const auto& localization = metrics["localization"];
  ASSERT_TRUE(localization["first_pose_frame"].is_number());
  EXPECT_LT(localization["first_pose_frame"].get<int>(), 30);
  EXPECT_GE(metrics["tracked"].get<double>(), 0.95 * 500);
  // Nothing was added: the map it ends with is the stored one.
  EXPECT_EQ(metrics["keyframes"], localization["stored_keyframes"]);
  EXPECT_EQ(metrics["map_resets"], 0);

  // Same frame as the mapping run: each pose against the mapping run's final pose of that frame,
  // with no alignment.
  const auto [rms, pairs] = distanceFromMappingRun(localize_out);
  ASSERT_GE(pairs, 450u);
  EXPECT_LT(rms, 0.03) << pairs << " poses, RMS " << rms * 100 << " cm from the mapping run's";

  // The route, judged by the truth: each checkpoint announced reached while the true position was
  // within 0.5 m of it (the paper's criterion; its robot reached 92.3 %).
  const auto& navigation = metrics["navigation"];
  EXPECT_GE(navigation["checkpoints"].get<int>(), 4);  // ~2.4 m of path in these frames
  ASSERT_TRUE(navigation.contains("success_rate"));
  EXPECT_EQ(navigation["alignment"]["by"], "stored keyframes");
  EXPECT_GE(navigation["success_rate"].get<double>(), 0.95);
  EXPECT_TRUE(navigation["arrived"].get<bool>());
  EXPECT_TRUE(std::filesystem::exists(localize_out / "instructions.csv"));

  // Read-only: the store is as the mapping run left it.
  EXPECT_EQ(fileBytes(*store_ / "maps.sqlite"), store_before);
  std::filesystem::remove_all(localize_out);
}

// The same frames through a real edge server: the client holds no map; the edge relocalises its
// first frames against the whole stored map and sends the part around it, then moves that window
// as the camera goes. Poses must be as good as local localisation's, the store untouched.
TEST_F(LocalizeOnly, AClientLocalisesThroughTheEdgeServerInItsStoredMap) {
  const auto out = test::freshTempDir("localize_edge_out");
  const auto logs = test::freshTempDir("localize_edge_logs");
  std::filesystem::create_directories(logs);
  const std::string store_before = fileBytes(*store_ / "maps.sqlite");
  const int port = 47500 + static_cast<int>(::getpid() % 400);
  const std::string address = "127.0.0.1:" + std::to_string(port);
  test::ChildProcess server(test::edgeslamBinary(),
                            words("server --listen " + address + " --status-every 0" + *vocab_ +
                                  " --semantic off --maps " + store_->string()),
                            logs / "server.log");
  ASSERT_TRUE(server.waitForLog("listening", std::chrono::seconds(60))) << server.log();
  const auto client =
      test::runEdgeslam("client --server " + address + " --dataset " + dataset() +
                        " --frames 500-999 --sensor rgbd --localize-only --map kitchen" + *vocab_ +
                        " --out " + out.string());
  ASSERT_EQ(client.exit_code, 0) << client.output << server.log();
  // A client lost later (the camera jumps back at the second pass) is found again by the edge.
  const auto jump_out = test::freshTempDir("localize_edge_jump");
  const auto jump = test::runEdgeslam("client --server " + address + " --dataset " + dataset() +
                                      " --frames 600-799 --repeat 2 --sensor rgbd --localize-only" +
                                      " --map kitchen" + *vocab_ + " --out " + jump_out.string());
  ASSERT_EQ(jump.exit_code, 0) << jump.output << server.log();
  server.signal(SIGTERM);
  EXPECT_TRUE(server.wait(std::chrono::seconds(60)).has_value());

  const auto metrics = readMetrics(out);
  SCOPED_TRACE(metrics.dump());
  EXPECT_EQ(metrics["mode"], "edge");
  const auto& localization = metrics["localization"];
  ASSERT_TRUE(localization["first_pose_frame"].is_number());
  EXPECT_LT(localization["first_pose_frame"].get<int>(), 30);
  EXPECT_GE(metrics["tracked"].get<double>(), 0.95 * 500);
  EXPECT_EQ(metrics["map_resets"], 0);
  // The edge found the place: the client had no map to relocalise in before its answer.
  EXPECT_GE(localization["edge"]["relocalized_by_edge"].get<int>(), 1);
  EXPECT_GE(localization["edge"]["window_moves"].get<int>(), 1);
  // The stored map's size as the edge reported it; the client held a window of it.
  EXPECT_GT(localization["stored_keyframes"].get<int>(), 30);

  const auto [rms, pairs] = distanceFromMappingRun(out);
  ASSERT_GE(pairs, 450u);
  EXPECT_LT(rms, 0.03) << pairs << " poses, RMS " << rms * 100 << " cm from the mapping run's";
  EXPECT_EQ(fileBytes(*store_ / "maps.sqlite"), store_before);

  const auto jumped = readMetrics(jump_out);
  SCOPED_TRACE(jumped.dump());
  EXPECT_GE(jumped["tracked"].get<double>(), 0.95 * 400);
  EXPECT_GE(jumped["localization"]["edge"]["relocalized_by_edge"].get<int>(), 2);
  EXPECT_EQ(jumped["map_resets"], 0);
  std::filesystem::remove_all(out);
  std::filesystem::remove_all(jump_out);
  std::filesystem::remove_all(logs);
}

TEST(LocalizeOnlyErrors, MissingStoreWrongModeAndNoMapNameAreClearErrors) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const std::string dataset = test::sharedPath(kSequence).string();
  const auto store = test::freshTempDir("localize_missing_store");
  const auto out = test::freshTempDir("localize_missing_out");
  const auto no_map = test::runEdgeslam("run --dataset " + dataset +
                                        " --mode local --localize-only --map nowhere --maps " +
                                        store.string() + " --out " + out.string());
  // No store in that folder: one line naming the file, a runtime error.
  EXPECT_EQ(no_map.exit_code, 1) << no_map.output;
  EXPECT_NE(no_map.output.find("maps.sqlite"), std::string::npos) << no_map.output;
  const auto offload =
      test::runEdgeslam("run --dataset " + dataset +
                        " --mode offload --localize-only --map kitchen --out " + out.string());
  EXPECT_EQ(offload.exit_code, 2) << offload.output;
  // Through the edge: the embedded edge's store is opened read-only, so a missing one is named.
  const auto edge_no_store = test::runEdgeslam(
      "run --dataset " + dataset + " --mode edge --localize-only --map nowhere --maps " +
      store.string() + " --out " + out.string());
  EXPECT_EQ(edge_no_store.exit_code, 1) << edge_no_store.output;
  EXPECT_NE(edge_no_store.output.find("maps.sqlite"), std::string::npos) << edge_no_store.output;
  const auto no_name = test::runEdgeslam("run --dataset " + dataset +
                                         " --mode local --localize-only --out " + out.string());
  EXPECT_EQ(no_name.exit_code, 2) << no_name.output;
  // A route is followed only when localising; a route the map lacks is named.
  const auto route_alone = test::runEdgeslam("run --dataset " + dataset +
                                             " --mode local --route walk --out " + out.string());
  EXPECT_EQ(route_alone.exit_code, 2) << route_alone.output;
  const auto no_route = test::runEdgeslam("route list --map kitchen --maps " + store.string());
  EXPECT_EQ(no_route.exit_code, 1) << no_route.output;
  std::filesystem::remove_all(store);
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace edgeslam
