// The readers on the real shared datasets (skipped with a message when they are absent).
#include <gtest/gtest.h>

#include <chrono>
#include <ctime>
#include <fstream>

#include "io/camera_file.h"
#include "io/dataset.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

using test::sharedPath;

constexpr const char* kSevenScenes = "datasets/7scenes-redkitchen-1000";
constexpr const char* kKitti = "datasets/kitti07-160";
constexpr const char* kTum = "datasets/tum-fr2desk-20";

TEST(SharedSevenScenes, FramesDepthAndGroundTruth) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  const auto folder = sharedPath(kSevenScenes);
  EXPECT_EQ(detectDatasetFormat(folder), DatasetFormat::kSevenScenes);
  auto reader = openDataset(folder);
  const DatasetInfo& info = reader->info();
  EXPECT_EQ(info.frame_count, 1000u);
  EXPECT_TRUE(info.has_depth);
  EXPECT_FALSE(info.has_stereo);
  EXPECT_TRUE(info.has_ground_truth);
  EXPECT_EQ(info.fps, 30.0);
  EXPECT_EQ(reader->camera().fx(), 585.0);
  EXPECT_EQ(reader->camera().cx(), 320.0);
  EXPECT_EQ(reader->camera().intrinsics().depth_factor, 1000.0);
  EXPECT_NEAR(reader->timestamps()[999], 999.0 / 30.0, 1e-9);

  const DatasetFrame frame = reader->load(0);
  EXPECT_EQ(frame.color.size(), cv::Size(640, 480));
  EXPECT_EQ(frame.color.type(), CV_8UC3);
  EXPECT_EQ(frame.gray.type(), CV_8UC1);
  ASSERT_EQ(frame.depth.type(), CV_32FC1);
  ASSERT_EQ(frame.depth.size(), cv::Size(640, 480));
  // An indoor kitchen: valid depth between 0.3 and 6 m, most pixels valid, median 0.7-4 m.
  cv::Mat valid = frame.depth > 0.0f;
  const int valid_count = cv::countNonZero(valid);
  EXPECT_GT(valid_count, 640 * 480 / 2);
  double min_depth = 0.0, max_depth = 0.0;
  cv::minMaxLoc(frame.depth, &min_depth, &max_depth, nullptr, nullptr, valid);
  EXPECT_GT(min_depth, 0.3);
  EXPECT_LT(max_depth, 6.0);
  std::vector<float> depths;
  for (int r = 0; r < frame.depth.rows; ++r) {
    for (int c = 0; c < frame.depth.cols; ++c) {
      if (frame.depth.at<float>(r, c) > 0.0f) depths.push_back(frame.depth.at<float>(r, c));
    }
  }
  std::nth_element(depths.begin(), depths.begin() + static_cast<std::ptrdiff_t>(depths.size() / 2),
                   depths.end());
  EXPECT_GT(depths[depths.size() / 2], 0.7);
  EXPECT_LT(depths[depths.size() / 2], 4.0);

  // Ground truth of frame 0 equals the file's matrix.
  std::ifstream pose_file(folder / "frame-000000.pose.txt");
  Eigen::Matrix4d expected;
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) pose_file >> expected(r, c);
  }
  ASSERT_TRUE(frame.ground_truth);
  // Translation exactly; rotation up to SE3d's re-orthonormalisation of KinectFusion's matrices.
  EXPECT_LT((frame.ground_truth->translation() - expected.topRightCorner<3, 1>()).norm(), 1e-12);
  EXPECT_LT((frame.ground_truth->matrix() - expected).cwiseAbs().maxCoeff(), 1e-4);
  EXPECT_NEAR(expected(0, 3), -0.34045634, 1e-8);  // the file really was read
}

TEST(SharedSevenScenes, GreyOnlyContentSkipsColourAndDepth) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  auto reader = openDataset(sharedPath(kSevenScenes));
  const DatasetFrame full = reader->load(7);
  reader->setContent({.color = false, .depth = false, .right = false});
  const DatasetFrame grey = reader->load(7);
  EXPECT_TRUE(grey.color.empty());
  EXPECT_TRUE(grey.depth.empty());
  ASSERT_EQ(grey.gray.size(), full.gray.size());
  ASSERT_EQ(grey.gray.type(), CV_8UC1);
  // Tracking sees the same grey image whatever else the run reads.
  EXPECT_EQ(cv::norm(grey.gray, full.gray, cv::NORM_INF), 0.0);
  EXPECT_EQ(grey.timestamp, full.timestamp);
  ASSERT_TRUE(grey.ground_truth.has_value());

  reader->setContent({.color = false, .depth = true, .right = false});
  const DatasetFrame with_depth = reader->load(7);
  EXPECT_TRUE(with_depth.color.empty());
  ASSERT_EQ(with_depth.depth.size(), full.depth.size());
  EXPECT_EQ(cv::norm(with_depth.depth, full.depth, cv::NORM_INF), 0.0);
}

TEST(SharedSevenScenes, LoadingAFrameTakesAFewMilliseconds) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  auto reader = openDataset(sharedPath(kSevenScenes));
  reader->load(0);  // warm the file cache
  constexpr int kLoads = 20;
  // CPU time of this thread, robust to other processes sharing the machine; wall time printed too.
  const auto cpu_ms = [] {
    timespec now{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &now);
    return static_cast<double>(now.tv_sec) * 1e3 + static_cast<double>(now.tv_nsec) * 1e-6;
  };
  const double cpu_start = cpu_ms();
  const auto wall_start = std::chrono::steady_clock::now();
  for (int i = 0; i < kLoads; ++i) reader->load(static_cast<std::size_t>(i));
  const double wall_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start)
          .count() /
      kLoads;
  const double cpu_per_frame_ms = (cpu_ms() - cpu_start) / kLoads;
  std::cout << "7-Scenes frame load (jpg + 16-bit png decode, grey, depth in metres): "
            << cpu_per_frame_ms << " ms CPU, " << wall_ms << " ms wall per frame\n";
  EXPECT_GT(cpu_per_frame_ms, 0.0);  // speed is reported, not asserted (shared, noisy machines)
}

TEST(SharedKitti, FramesTimesPosesAndCalibration) {
  EDGESLAM_REQUIRE_SHARED(kKitti);
  const auto folder = sharedPath(kKitti);
  EXPECT_EQ(detectDatasetFormat(folder), DatasetFormat::kKitti);
  auto reader = openDataset(folder);
  const DatasetInfo& info = reader->info();
  EXPECT_EQ(info.frame_count, 160u);
  EXPECT_FALSE(info.has_depth);
  EXPECT_FALSE(info.has_stereo);
  EXPECT_TRUE(info.has_ground_truth);
  EXPECT_NEAR(info.fps, 10.0, 0.5);
  EXPECT_EQ(reader->camera().width(), 1226);
  EXPECT_EQ(reader->camera().height(), 370);
  EXPECT_EQ(reader->camera().fx(), 707.0912);
  EXPECT_EQ(reader->camera().cy(), 183.1104);
  EXPECT_NEAR(reader->camera().intrinsics().baseline_m, 0.53715065, 1e-7);
  EXPECT_NEAR(reader->timestamps()[1], 0.1038752, 1e-9);

  const DatasetFrame frame = reader->load(1);
  EXPECT_EQ(frame.gray.size(), cv::Size(1226, 370));
  EXPECT_TRUE(frame.color.empty());
  EXPECT_EQ(frame.name, "000001.png");
  ASSERT_TRUE(frame.ground_truth);
  EXPECT_NEAR(frame.ground_truth->translation().x(), -4.596714e-03, 1e-9);
  EXPECT_NEAR(frame.ground_truth->translation().z(), 9.154274e-02, 1e-9);
  ASSERT_TRUE(reader->groundTruth()[159]);
  EXPECT_GT(reader->groundTruth()[159]->translation().norm(), 10.0);  // a car drove 16 s

  // The shipped camera file agrees with calib.txt.
  const CameraIntrinsics shipped =
      loadCameraFile(std::filesystem::path(EDGESLAM_SOURCE_DIR) / "config/cameras/kitti07.yaml");
  EXPECT_DOUBLE_EQ(shipped.fx, reader->camera().fx());
  EXPECT_DOUBLE_EQ(shipped.cx, reader->camera().cx());
  EXPECT_NEAR(shipped.baseline_m, reader->camera().intrinsics().baseline_m, 1e-12);
}

TEST(SharedTum, Fr2DeskCameraAndInterpolatedGroundTruth) {
  EDGESLAM_REQUIRE_SHARED(kTum);
  const auto folder = sharedPath(kTum);
  EXPECT_EQ(detectDatasetFormat(folder), DatasetFormat::kTum);
  auto reader = openDataset(folder);
  const DatasetInfo& info = reader->info();
  EXPECT_EQ(info.frame_count, 20u);
  EXPECT_FALSE(info.has_depth);
  EXPECT_NEAR(info.fps, 10.0, 0.5);  // every 3rd frame of a 30 Hz recording
  // Freiburg 2 recognised from the folder name.
  EXPECT_DOUBLE_EQ(reader->camera().fx(), 520.908620);
  EXPECT_DOUBLE_EQ(reader->camera().intrinsics().distortion.k1, 0.231222);
  EXPECT_EQ(reader->camera().intrinsics().depth_factor, 5000.0);

  for (std::size_t i = 0; i < info.frame_count; ++i) {
    EXPECT_TRUE(reader->groundTruth()[i]) << "frame " << i;
  }
  // Frame 0 at 1311868169.163498 lies between the samples
  //   1311868169.1634 -0.0607 -2.1082 1.5029 0.7407 -0.4308 0.2530 -0.4493
  //   1311868169.1667 -0.0600 -2.1084 1.5032 0.7411 -0.4303 0.2527 -0.4492
  // s = 0.000098 / 0.0033 = 0.0296970, so t = (-0.0606792, -2.1082059, 1.5029089).
  const DatasetFrame frame = reader->load(0);
  EXPECT_NEAR(frame.timestamp, 1311868169.163498, 1e-6);
  ASSERT_TRUE(frame.ground_truth);
  EXPECT_NEAR(frame.ground_truth->translation().x(), -0.0606792, 1e-6);
  EXPECT_NEAR(frame.ground_truth->translation().y(), -2.1082059, 1e-6);
  EXPECT_NEAR(frame.ground_truth->translation().z(), 1.5029089, 1e-6);
  const Eigen::Quaterniond q0(-0.4493, 0.7407, -0.4308, 0.2530),
      q1(-0.4492, 0.7411, -0.4303, 0.2527);
  const Eigen::Quaterniond nlerp(
      ((1 - 0.029697) * q0.normalized().coeffs() + 0.029697 * q1.normalized().coeffs())
          .normalized());
  EXPECT_LT(frame.ground_truth->rotation().angularDistance(nlerp), 1e-6);
  EXPECT_EQ(frame.color.size(), cv::Size(640, 480));
  EXPECT_TRUE(frame.depth.empty());
}

TEST(SharedDatasets, ExplicitFormatMatchesAutoDetection) {
  EDGESLAM_REQUIRE_SHARED(kTum);
  DatasetOptions options;
  options.format = DatasetFormat::kTum;
  EXPECT_EQ(openDataset(sharedPath(kTum), options)->info().frame_count, 20u);
  options.format = DatasetFormat::kSevenScenes;
  EXPECT_THROW(openDataset(sharedPath(kTum), options), DatasetError);
}

TEST(SharedDatasets, CameraOverrideFromShippedFile) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  DatasetOptions options;
  options.camera_override =
      loadCameraFile(std::filesystem::path(EDGESLAM_SOURCE_DIR) / "config/cameras/tum-fr3.yaml");
  auto reader = openDataset(sharedPath(kSevenScenes), options);
  EXPECT_EQ(reader->camera().fx(), 535.4);
  // The override's depth_factor (5000) applies: depth comes out 5x smaller than in millimetres.
  EXPECT_EQ(reader->camera().intrinsics().depth_factor, 5000.0);
  options.camera_override =
      loadCameraFile(std::filesystem::path(EDGESLAM_SOURCE_DIR) / "config/cameras/kitti07.yaml");
  EXPECT_THROW(openDataset(sharedPath(kSevenScenes), options), DatasetError);  // 1226x370
}

}  // namespace
}  // namespace edgeslam
