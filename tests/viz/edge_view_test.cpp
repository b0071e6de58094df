// The edge view's directory of sessions, its snapshot and one map's encoding, without a server
// (the browser test drives the real `server --viewer` with real clients; the shared-map test
// watches it through a merge).
#include "viz/edge_view.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "store/store_fixture.h"
#include "viz/edge_map_json.h"

namespace edgeslam::viz {
namespace {

TEST(EdgeView, ListsSessionsWithTheServersFiguresAndTheirComingsAndGoings) {
  auto directory = std::make_shared<SessionDirectory>();
  EdgeView view(directory, EdgeViewOptions{.refresh = std::chrono::milliseconds(0)});
  directory->opened(
      {.session_id = 7, .client_name = "phone", .sensor = "rgbd", .map_name = "", .backend = {}});
  view.setStatsSource([] {
    SessionStats stats;
    stats.session_id = 7;
    stats.uplink_bytes = 1234;
    return std::vector<SessionStats>{stats};
  });
  auto snapshot = nlohmann::json::parse(view.snapshotJson());
  EXPECT_EQ(snapshot["view"], "edge");
  ASSERT_EQ(snapshot["sessions"].size(), 1u);
  EXPECT_EQ(snapshot["sessions"][0]["session_id"], "7");
  EXPECT_EQ(snapshot["sessions"][0]["client_name"], "phone");
  EXPECT_EQ(snapshot["sessions"][0]["uplink_bytes"], 1234);
  EXPECT_TRUE(snapshot["sessions"][0]["camera"].is_null());  // no map yet
  const auto version = snapshot["version"].get<std::uint64_t>();
  // Unchanged: the same version; a session leaving: a new one, listed in the events.
  EXPECT_EQ(nlohmann::json::parse(view.snapshotJson())["version"], version);
  directory->closed(7);
  view.clearStatsSource();
  snapshot = nlohmann::json::parse(view.snapshotJson());
  EXPECT_GT(snapshot["version"].get<std::uint64_t>(), version);
  EXPECT_EQ(snapshot["sessions"].size(), 0u);
  EXPECT_EQ(snapshot["status"]["sessions_opened"], 1);
  ASSERT_EQ(snapshot["events"].size(), 2u);
  EXPECT_NE(snapshot["events"][0]["text"].get<std::string>().find("joined"), std::string::npos);
  EXPECT_NE(snapshot["events"][1]["text"].get<std::string>().find("left"), std::string::npos);
}

SE3d cameraAt(double x) {
  return SE3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, 0, 0));
}

KeyFrameId idOf(std::uint8_t origin, std::uint64_t n) {
  return (static_cast<std::uint64_t>(origin) << 56) | n;
}

RouteRecord walkRoute() {
  RouteRecord route;
  route.name = "walk";
  route.checkpoints = {{0, 0, 0}, {1, 0, 0}};
  return route;
}

TEST(EdgeMapJson, OneTrajectoryPerClientAndLoopsAndMergesBetweenKeyFrames) {
  EdgeMapContent map;
  // Two clients' keyframes interleaved, as a shared map holds them; client 2's out of order.
  for (auto [origin, n, x] : {std::tuple{1, 1, 0.0}, {2, 5, 3.0}, {1, 2, 1.0}, {2, 4, 2.0}}) {
    map.sample.keyframe_ids.push_back(idOf(static_cast<std::uint8_t>(origin), n));
    map.sample.keyframe_poses.push_back(cameraAt(x));
  }
  map.sample.points = {{0, 1, 2}};
  map.sample.total_points = 10;
  LoopEvent loop;
  loop.current = idOf(2, 5);
  loop.loop = idOf(1, 1);
  loop.current_frame = 500;
  loop.loop_frame = 20;
  LoopEvent merge = loop;
  merge.keyframes_merged = 12;
  LoopEvent gone = loop;
  gone.loop = idOf(1, 99);  // culled since
  map.loops = {loop, merge, gone};
  map.routes = {walkRoute()};

  const nlohmann::json j = edgeMapJson(map, 100);
  EXPECT_EQ(j["keyframe_count"], 4);
  EXPECT_EQ(j["map_points"], 10);
  EXPECT_EQ(j["points"].size(), 3u);
  ASSERT_EQ(j["trajectories"].size(), 2u);
  EXPECT_EQ(j["trajectories"][0]["origin"], 1);
  EXPECT_EQ(j["trajectories"][0]["positions"], nlohmann::json({0.0, 0.0, 0.0, 1.0, 0.0, 0.0}));
  EXPECT_EQ(j["trajectories"][1]["origin"], 2);  // in the order they were made: 4 before 5
  EXPECT_EQ(j["trajectories"][1]["positions"], nlohmann::json({2.0, 0.0, 0.0, 3.0, 0.0, 0.0}));
  ASSERT_EQ(j["loops"].size(), 2u);
  EXPECT_FALSE(j["loops"][0]["merge"].get<bool>());
  EXPECT_TRUE(j["loops"][1]["merge"].get<bool>());
  EXPECT_EQ(j["loops"][1]["from"], nlohmann::json({3.0, 0.0, 0.0}));
  EXPECT_EQ(j["loops"][1]["to"], nlohmann::json({0.0, 0.0, 0.0}));
  EXPECT_EQ(j["loops"][1]["frames"], nlohmann::json({500, 20}));
  ASSERT_EQ(j["routes"].size(), 1u);
  EXPECT_EQ(j["routes"][0]["checkpoints"].size(), 6u);
  EXPECT_EQ(edgeMapJson(map, 2)["keyframes"].size(), 2u);  // bounded, evenly spaced

  const std::optional<SE3d> newest = newestKeyFrameOf(map.sample, 2);
  ASSERT_TRUE(newest);
  EXPECT_DOUBLE_EQ(newest->translation().x(), 3.0);
  EXPECT_FALSE(newestKeyFrameOf(map.sample, 3));
}

TEST(EdgeView, ListsTheStoresMapsAndShowsOneOnRequest) {
  const auto dir = test::freshStoreDir("edge_view");
  {
    auto store = openMapStore(dir, MapStoreAccess::kServe);
    test::writeSmallMap(*store, "kitchen");
    store->saveRoute("kitchen", walkRoute());
  }
  auto directory = std::make_shared<SessionDirectory>();
  EdgeView view(directory, EdgeViewOptions{.refresh = std::chrono::milliseconds(0)});
  EXPECT_FALSE(view.storedMapJson("kitchen"));  // no store yet
  view.setStore(openMapStore(dir, MapStoreAccess::kServe));

  const auto snapshot = nlohmann::json::parse(view.snapshotJson());
  ASSERT_EQ(snapshot["maps"].size(), 1u);
  const auto& listed = snapshot["maps"][0];
  EXPECT_EQ(listed["name"], "kitchen");
  EXPECT_FALSE(listed["live"].get<bool>());
  EXPECT_EQ(listed["keyframe_count"], 3);
  EXPECT_GT(listed["stored"]["points"].get<int>(), 100);
  EXPECT_FALSE(listed.contains("points"));  // a stored map's content comes on request

  const std::optional<std::string> shown = view.storedMapJson("kitchen");
  ASSERT_TRUE(shown);
  const auto map = nlohmann::json::parse(*shown);
  EXPECT_EQ(map["name"], "kitchen");
  EXPECT_EQ(map["keyframe_count"], 3);
  EXPECT_EQ(map["points"].size(), 3 * listed["stored"]["points"].get<std::size_t>());
  ASSERT_EQ(map["trajectories"].size(), 1u);
  EXPECT_EQ(map["trajectories"][0]["positions"].size(), 9u);
  ASSERT_EQ(map["routes"].size(), 1u);
  EXPECT_EQ(map["routes"][0]["name"], "walk");
  EXPECT_EQ(view.storedMapJson("kitchen"), shown);  // kept while the map is unchanged
  EXPECT_FALSE(view.storedMapJson("nowhere"));
}

}  // namespace
}  // namespace edgeslam::viz
