#include "viz/view_snapshot.h"

#include <gtest/gtest.h>

#include <limits>

namespace edgeslam::viz {
namespace {

ViewSnapshot exampleSnapshot() {
  ViewSnapshot s;
  s.version = 7;
  s.status.frame = 12;
  s.status.frames_total = 300;
  s.status.fps = 29.87;
  s.status.state = "ok";
  s.status.tracked_points = 321;
  s.status.keyframes = 4;
  s.status.map_points = 5000;
  s.status.client_ms = 11.234;
  s.status.uplink_bytes = 1234;
  s.status.mode = "local";
  s.status.sensor = "rgbd";
  s.camera = ViewPose{{1.0, 2.0, 3.0}, Eigen::Quaterniond::Identity()};
  s.trajectory = {{0, 0, 0}, {0.1234567, 0.2, 0.3}};
  s.keyframes = {
      ViewPose{{0, 0, 0}, Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY()))}};
  s.points = {{1, 1, 1}, {2, 2, 2}, {3, 3, 3}};
  s.points_total = 5000;
  return s;
}

TEST(VizSnapshotJson, HasEveryField) {
  const nlohmann::json j = toJson(exampleSnapshot());
  for (const char* key : {"version", "status", "camera", "trajectory", "ground_truth", "keyframes",
                          "points", "points_total"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  for (const char* key :
       {"frame", "frames_total", "fps", "state", "tracked_points", "keyframes", "map_points",
        "client_ms", "uplink_bytes", "downlink_bytes", "mode", "sensor", "finished"}) {
    EXPECT_TRUE(j["status"].contains(key)) << key;
  }
  EXPECT_EQ(j["status"]["frame"], 12);
  EXPECT_EQ(j["status"]["state"], "ok");
  EXPECT_EQ(j["status"]["mode"], "local");
  EXPECT_DOUBLE_EQ(j["status"]["client_ms"].get<double>(), 11.23);
  EXPECT_EQ(j["camera"]["position"], nlohmann::json({1.0, 2.0, 3.0}));
  EXPECT_EQ(j["camera"]["orientation"].size(), 4u);
  EXPECT_EQ(j["keyframes"].size(), 1u);
  EXPECT_EQ(j["keyframes"][0]["orientation"].size(), 4u);
  // Flat triples, rounded to the millimetre.
  EXPECT_EQ(j["trajectory"].size(), 6u);
  EXPECT_DOUBLE_EQ(j["trajectory"][3].get<double>(), 0.123);
  EXPECT_EQ(j["points"].size(), 9u);
  EXPECT_EQ(j["ground_truth"].size(), 0u);
  EXPECT_EQ(j["route"].size(), 0u);
  EXPECT_EQ(j["status"]["checkpoint"], -1);
}

TEST(VizSnapshotJson, CarriesTheRouteFollowedAndItsNextCheckpoint) {
  ViewSnapshot s = exampleSnapshot();
  s.route = {{0, 0, 0}, {1, 0, 0}, {1, 0, 2}};
  s.status.instruction = "go straight to checkpoint 2 of 3 (0.80 m)";
  s.status.checkpoint = 1;
  const nlohmann::json j = toJson(s);
  EXPECT_EQ(j["route"], nlohmann::json({0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 2.0}));
  EXPECT_EQ(j["status"]["checkpoint"], 1);
  EXPECT_EQ(j["status"]["instruction"], s.status.instruction);
}

TEST(VizSnapshotJson, NoCameraIsNull) {
  ViewSnapshot s = exampleSnapshot();
  s.camera.reset();
  EXPECT_TRUE(toJson(s)["camera"].is_null());
}

TEST(VizSnapshotJson, LeavesOutWhatIsNotFinite) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  ViewSnapshot s = exampleSnapshot();
  s.status.fps = nan;
  s.status.client_ms = inf;
  s.camera = ViewPose{{nan, 0, 0}, Eigen::Quaterniond::Identity()};
  s.trajectory.push_back({inf, 0, 0});
  s.points.push_back({0, nan, 0});
  s.keyframes.push_back(ViewPose{{0, 0, 0}, Eigen::Quaterniond(nan, 0, 0, 0)});
  const nlohmann::json j = toJson(s);
  EXPECT_EQ(j["trajectory"].size(), 6u);
  EXPECT_EQ(j["points"].size(), 9u);
  EXPECT_EQ(j["keyframes"].size(), 1u);
  EXPECT_TRUE(j["camera"].is_null());
  EXPECT_EQ(j["status"]["fps"], 0.0);
  const std::string text = j.dump();
  EXPECT_EQ(text.find("NaN"), std::string::npos);
  EXPECT_EQ(text.find("nan"), std::string::npos);
  EXPECT_EQ(text.find("inf"), std::string::npos);
  EXPECT_TRUE(nlohmann::json::accept(text));
}

}  // namespace
}  // namespace edgeslam::viz
