#include "viz/live_view.h"

#include <gtest/gtest.h>

#include <atomic>

namespace edgeslam::viz {
namespace {

SE3d at(double x, double y, double z) {
  return SE3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(x, y, z));
}

MapSample manyPoints(std::size_t keyframes, std::size_t points, std::size_t max_points) {
  MapSample sample;
  for (std::size_t i = 0; i < keyframes; ++i) sample.keyframe_poses.push_back(at(double(i), 0, 0));
  for (std::size_t i = 0; i < std::min(points, max_points); ++i) {
    sample.points.push_back({double(i), 1, 2});
  }
  sample.total_points = points;
  return sample;
}

TEST(VizLiveView, BoundsTrajectoryKeyframesAndPoints) {
  LiveViewOptions options;
  options.max_trajectory_poses = 100;
  options.max_points = 500;
  options.max_keyframes = 50;
  LiveView view(options);
  view.setMapSampler([](std::size_t max_points) { return manyPoints(400, 100000, max_points); });
  RunStatus status;
  for (int i = 0; i < 10000; ++i) {
    status.frame = static_cast<std::size_t>(i + 1);
    view.publishFrame(status, at(i * 0.01, 0, 0), std::nullopt);
  }
  const ViewSnapshot s = view.snapshot();
  EXPECT_EQ(s.version, 10000u);
  EXPECT_EQ(s.status.frame, 10000u);
  EXPECT_LE(s.trajectory.size(), 100u);
  EXPECT_EQ(s.points.size(), 500u);
  EXPECT_EQ(s.points_total, 100000u);
  EXPECT_EQ(s.keyframes.size(), 50u);
  EXPECT_EQ(s.keyframes.back().position.x(), 399.0);  // the newest kept
  ASSERT_TRUE(s.camera.has_value());
  EXPECT_NEAR(s.camera->position.x(), 99.99, 1e-9);
  EXPECT_TRUE(s.ground_truth.empty());
  const nlohmann::json j = nlohmann::json::parse(view.snapshotJson());
  EXPECT_LE(j["trajectory"].size(), 300u);
  EXPECT_EQ(j["points"].size(), 1500u);
}

TEST(VizLiveView, SamplesTheMapAtMostOncePerRefresh) {
  LiveViewOptions options;
  options.map_refresh = std::chrono::hours(1);
  LiveView view(options);
  std::atomic<int> samples{0};
  view.setMapSampler([&samples](std::size_t max_points) {
    ++samples;
    return manyPoints(3, 10, max_points);
  });
  for (int i = 0; i < 20; ++i) {
    view.publishFrame(RunStatus{}, at(0, 0, i), std::nullopt);
    (void)view.snapshotJson();
  }
  EXPECT_EQ(samples.load(), 1);
  view.clearMapSampler();
  EXPECT_EQ(view.snapshot().keyframes.size(), 3u);  // the last sample stays
}

TEST(VizLiveView, GroundTruthIsAnchoredAtTheFirstFrame) {
  LiveView view;
  // The estimate starts at the origin; the dataset's frame is shifted by (10, 0, 0).
  view.publishFrame(RunStatus{}, at(0, 0, 0), at(10, 0, 0));
  view.publishFrame(RunStatus{}, at(1, 0, 0), at(11, 0, 0));
  const ViewSnapshot s = view.snapshot();
  ASSERT_EQ(s.ground_truth.size(), 2u);
  EXPECT_NEAR(s.ground_truth[0].x(), 0.0, 1e-12);
  EXPECT_NEAR(s.ground_truth[1].x(), 1.0, 1e-12);
}

TEST(VizLiveView, EncodesOncePerChange) {
  LiveView view;
  view.publishFrame(RunStatus{}, at(0, 0, 0), std::nullopt);
  const std::string first = view.snapshotJson();
  EXPECT_EQ(view.snapshotJson(), first);
  view.markFinished();
  const nlohmann::json j = nlohmann::json::parse(view.snapshotJson());
  EXPECT_TRUE(j["status"]["finished"].get<bool>());
}

}  // namespace
}  // namespace edgeslam::viz
