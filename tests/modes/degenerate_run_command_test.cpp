// Degenerate input that looks valid, as a user runs it: image folders made from real 7-Scenes
// frames (a camera that does not move; a real walk with a blank stretch, a duplicated frame and a
// frame from the past; a walk that ends in a pure rotation) and KITTI 03 at highway speed, through
// `edgeslam run`. No map may be built from the still camera, no pose reported for a blank frame,
// no confident pose that is wrong, and metrics.json must say why.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "eval/association.h"
#include "eval/ate.h"
#include "io/dataset.h"
#include "io/temp_folder.h"
#include "io/trajectory.h"
#include "support/edgeslam_command.h"
#include "support/image_folder_sequence.h"
#include "support/shared_data.h"
#include "synth/degenerate_frames.h"

namespace edgeslam {
namespace {

namespace fs = std::filesystem;
constexpr const char* kKitchen = "datasets/7scenes-redkitchen-1000";
constexpr const char* kKitti03 = "datasets/kitti03-400";
constexpr double kPi = 3.14159265358979323846;

nlohmann::json run(const fs::path& dataset, const fs::path& out, const std::string& mode) {
  const auto r = test::runEdgeslam("run --dataset " + dataset.string() +
                                   " --sensor mono --vocab none --maps none --mode " + mode +
                                   " --out " + out.string());
  EXPECT_EQ(r.exit_code, 0) << r.output;
  std::ifstream in(out / "metrics.json");
  if (!in) return {};
  return nlohmann::json::parse(in);
}

TEST(DegenerateRun, StillCameraBuildsNoMapAndMetricsSayLowParallax) {
  EDGESLAM_REQUIRE_SHARED(kKitchen);
  test::TempFolder folder;
  const fs::path still = folder / "still";
  const cv::Mat frame = openDataset(test::sharedPath(kKitchen))->load(100).gray;
  std::vector<test::StampedImage> frames;
  for (std::size_t i = 0; i < 30; ++i) frames.push_back({frame, static_cast<double>(i) / 30.0});
  test::writeImageFolder(still, frames);

  const auto m = run(still, folder / "out", "edge");
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m["tracked"], 0);
  EXPECT_EQ(m["keyframes"], 0);
  const auto& init = m["initialization"];
  ASSERT_TRUE(init.is_object()) << m.dump(2);
  EXPECT_EQ(init["map_built"], false);
  EXPECT_EQ(init["at_frame"], nullptr);
  EXPECT_EQ(init["frames_without_map"], 30);
  EXPECT_EQ(init["refused"]["low_parallax"], 29) << init.dump(2);
  EXPECT_NE(init["last_refusal"].get<std::string>().find("pure rotation or too little"),
            std::string::npos);
  ASSERT_EQ(m["warnings"].size(), 1u) << m.dump(2);
  EXPECT_NE(m["warnings"][0].get<std::string>().find("no map was built"), std::string::npos);
}

TEST(DegenerateRun, BlankStretchAndDisorderedFramesAreCountedNotTracked) {
  EDGESLAM_REQUIRE_SHARED(kKitchen);
  test::TempFolder folder;
  const fs::path walk = folder / "walk";
  test::writeImageFolder(walk, test::walkWithDisorder(*openDataset(test::sharedPath(kKitchen))));

  const auto m = run(walk, folder / "out", "local");
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m["frames"], 142);
  EXPECT_EQ(m["frames_out_of_order"]["skipped"], 2);
  EXPECT_EQ(m["frames_out_of_order"]["duplicate_timestamp"], 1);
  EXPECT_EQ(m["frames_out_of_order"]["timestamp_backwards"], 1);
  EXPECT_EQ(m["initialization"]["map_built"], true);
  EXPECT_EQ(m["lost_frames"]["too_few_features"], 10) << m.dump(2);
  EXPECT_EQ(m["lost"], m["lost_frames"]["too_few_features"].get<int>() +
                           m["lost_frames"]["tracking_failed"].get<int>());
  // Tracking resumed after the white stretch: all but the 10 white frames and the frames before
  // the map are tracked.
  const int before_map = m["initialization"]["frames_without_map"].get<int>();
  EXPECT_GE(m["tracked"].get<int>(), 140 - 10 - before_map - 5) << m.dump(2);
}

// Every `stride`-th frame of a KITTI sequence as a sequence of its own (images linked, poses and
// times renumbered): at stride 3 the car of KITTI 03 moves ~1.9 m a frame at 10 Hz (~68 km/h).
void writeKittiAtStride(const fs::path& from, const fs::path& to, std::size_t stride,
                        std::size_t count) {
  fs::create_directories(to / "image_0");
  fs::copy_file(from / "calib.txt", to / "calib.txt");
  const std::vector<SE3d> poses = readKittiPoses(from / "poses.txt");
  const std::vector<double> times = readTimes(from / "times.txt");
  std::vector<SE3d> kept_poses;
  std::ofstream kept_times(to / "times.txt");
  kept_times << std::setprecision(12);
  for (std::size_t i = 0; i < count && i * stride < poses.size(); ++i) {
    char from_name[32];
    char to_name[32];
    std::snprintf(from_name, sizeof(from_name), "%06zu.jpg", i * stride);
    std::snprintf(to_name, sizeof(to_name), "%06zu.jpg", i);
    fs::create_symlink(from / "image_0" / from_name, to / "image_0" / to_name);
    kept_poses.push_back(poses[i * stride]);
    kept_times << times[i * stride] << "\n";
  }
  writeKittiPoses(to / "poses.txt", kept_poses);
}

double pathLength(const std::vector<SE3d>& poses) {
  double length = 0.0;
  for (std::size_t i = 1; i < poses.size(); ++i) {
    length += (poses[i].translation() - poses[i - 1].translation()).norm();
  }
  return length;
}

// Forward motion at highway speed gives thin maps (little parallax ahead, large changes in
// scale): the tracker may lose the road, but every pose it reports must be right, and what it
// could not track must be counted, with its cause, and warned about.
TEST(DegenerateRun, HighwaySpeedForwardMotionReportsOnlyPosesItCanTrust) {
  EDGESLAM_REQUIRE_SHARED(kKitti03);
  test::TempFolder folder;
  const fs::path highway = folder / "highway";
  writeKittiAtStride(test::sharedPath(kKitti03), highway, 3, 51);
  const double path_m = pathLength(readKittiPoses(highway / "poses.txt"));
  ASSERT_GT(path_m, 80.0);

  // Lock-step threads: free-running, about 1 run in 6 tracks the whole stretch but loses scale at
  // frames 35-45 (steps 2-3x too short; ATE 1.3-6.2 m, 8 of 44 runs in session 26), a spread
  // issue of its own (docs/faults.md); this test is about what a degenerate input may report.
  const auto m = run(highway, folder / "out", "local --deterministic");
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(m["frames"], 51);
  const int tracked = m["tracked"].get<int>();
  const int lost = m["lost"].get<int>();
  const int without_map = m["initialization"]["frames_without_map"].get<int>();
  // Every frame is accounted for: tracked, lost, without a map, or tracked in a map that a reset
  // discarded (its poses withdrawn).
  EXPECT_GE(tracked + lost + without_map + m["tracked_in_discarded_maps"].get<int>(), 51)
      << m.dump(2);
  EXPECT_EQ(lost, m["lost_frames"]["too_few_features"].get<int>() +
                      m["lost_frames"]["tracking_failed"].get<int>());
  ASSERT_GE(tracked, 5) << "no map at all on a textured road";
  // A confident wrong pose is the failure: every reported pose within 1 % of the drive.
  // The poses evaluated are the tracked frames' and the map's first reference frame; frames
  // tracked in a new map (started after the loss; this drive never returns to merge it) are in
  // its own file, and held to the same bound in their own frame.
  const int own = m["tracked_in_own_frames"]["at_frame_time"].get<int>();
  const int maps_started = static_cast<int>(m["maps_started_at"].size());
  EXPECT_EQ(own, m["tracked_in_own_frames"]["never_merged"].get<int>());
  // Each map's first reference frame (monocular) has a pose too, though not counted as tracked.
  const int pairs = m["ate"]["pairs"].get<int>();
  EXPECT_GE(pairs + own, tracked);
  EXPECT_LE(pairs + own, tracked + 1 + maps_started);
  EXPECT_LT(m["ate"]["rmse_m"].get<double>(), 0.01 * path_m) << m["ate"].dump();
  const Trajectory truth = readTumTrajectory(folder / "out" / "groundtruth.tum");
  int own_in_files = 0;
  for (int k = 1; k <= maps_started; ++k) {
    const fs::path file = folder / "out" / ("trajectory_map" + std::to_string(k) + ".tum");
    if (!fs::exists(file)) continue;
    const PosePairs map_pairs = associateByTimestamp(truth, readTumTrajectory(file));
    own_in_files += static_cast<int>(map_pairs.size());
    if (map_pairs.size() < 3) continue;
    const double rmse = computeAte(map_pairs, AlignMode::kSim3).translation.rmse;
    EXPECT_LT(rmse, 0.01 * path_m) << file;
    std::cout << "highway: " << map_pairs.size() << " frames in new map " << k
              << ", ATE (sim3, its own frame) " << rmse << " m\n";
  }
  EXPECT_EQ(own_in_files, own);
  std::cout << "highway: tracked " << tracked << " (+" << m["tracked_in_discarded_maps"]
            << " in a discarded map), lost " << lost << ", without a map " << without_map
            << ", ATE (sim3) " << m["ate"]["rmse_m"].get<double>() << " m over " << path_m
            << " m\n";
  if (lost > 0) {
    bool warned = false;
    for (const auto& warning : m["warnings"]) {
      warned = warned || warning.get<std::string>().find("tracking lost") != std::string::npos;
    }
    EXPECT_TRUE(warned) << m["warnings"].dump();
  }
}

// A camera that only rotates once the map exists gives no parallax for new points, but the map
// it has fixes the rotation: the pan is tracked as a pan, frame by frame, and the camera centre
// stays where it was (the ground truth of the panned frames is the last real pose turned by the
// pan, exactly what the warp K R K^-1 shows).
TEST(DegenerateRun, PureRotationAfterTheMapIsTrackedAsARotation) {
  EDGESLAM_REQUIRE_SHARED(kKitchen);
  test::TempFolder folder;
  const fs::path walk = folder / "walk_then_pan";
  auto reader = openDataset(test::sharedPath(kKitchen));
  const Eigen::Matrix3d K = reader->camera().K();
  constexpr std::size_t kWalk = 60;
  constexpr std::size_t kPan = 30;
  constexpr double kDegreesPerFrame = 0.5;
  std::vector<test::StampedImage> frames;
  Trajectory truth;
  for (std::size_t i = 0; i < kWalk; ++i) {
    const DatasetFrame frame = reader->load(i);
    ASSERT_TRUE(frame.ground_truth.has_value());
    frames.push_back({frame.gray, static_cast<double>(i) / 30.0});
    truth.push_back({frames.back().timestamp, *frame.ground_truth});
  }
  const cv::Mat last = frames.back().image;
  const SE3d last_pose = truth.back().pose;
  for (std::size_t k = 1; k <= kPan; ++k) {
    const Eigen::Matrix3d after_from_before =
        panRotation(kDegreesPerFrame * static_cast<double>(k));
    const double t = static_cast<double>(kWalk - 1 + k) / 30.0;
    frames.push_back({rotatedView(last, K, after_from_before), t});
    truth.push_back({t, last_pose * SE3d(Eigen::Matrix3d(after_from_before.transpose()),
                                         Eigen::Vector3d::Zero())});
  }
  test::writeImageFolder(walk, frames);
  writeTumTrajectory(walk / "groundtruth.txt", truth);

  const auto m = run(walk, folder / "out", "local");
  ASSERT_FALSE(m.empty());
  ASSERT_EQ(m["initialization"]["map_built"], true) << m.dump(2);
  const Trajectory estimate = readTumTrajectory(folder / "out" / "trajectory.tum");
  const double last_walk_time = static_cast<double>(kWalk - 1) / 30.0;
  const StampedPose* before_pan = nullptr;
  for (const StampedPose& pose : estimate) {
    if (std::abs(pose.timestamp - last_walk_time) < 1e-6) before_pan = &pose;
  }
  ASSERT_NE(before_pan, nullptr) << "the last frame before the pan was not tracked";
  std::size_t panned_tracked = 0;
  double worst_turn_error_deg = 0.0;
  for (const StampedPose& pose : estimate) {
    if (pose.timestamp < last_walk_time + 1e-6) continue;
    ++panned_tracked;
    const double k = std::round((pose.timestamp - last_walk_time) * 30.0);
    const double turned_deg = rotationDistance(pose.pose, before_pan->pose) * 180.0 / kPi;
    EXPECT_NEAR(turned_deg, kDegreesPerFrame * k, 0.5) << "panned frame " << k;
    worst_turn_error_deg =
        std::max(worst_turn_error_deg, std::abs(turned_deg - kDegreesPerFrame * k));
  }
  std::cout << "pan: " << panned_tracked << " of " << kPan
            << " panned frames tracked, worst turn error " << worst_turn_error_deg
            << " deg, ATE (sim3) " << m["ate"]["rmse_m"].get<double>() * 100.0 << " cm, keyframes "
            << m["keyframes"] << ", points " << m["map_points"] << "\n";
  EXPECT_GE(panned_tracked, kPan - 2) << m.dump(2);
  // The camera centre must not wander during the pan: the whole run, walk and pan, stays within
  // the walk's accuracy (sim3: monocular scale).
  EXPECT_LT(m["ate"]["rmse_m"].get<double>(), 0.05) << m["ate"].dump();
}

}  // namespace
}  // namespace edgeslam
