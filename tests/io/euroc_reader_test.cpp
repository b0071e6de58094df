// A tiny synthetic EuRoC folder (ASL layout, OpenCV-style %YAML:1.0 sensor files).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdint>

#include "io/dataset.h"
#include "temp_folder.h"

namespace edgeslam {
namespace {

using test::TempFolder;
using test::writeText;

constexpr std::int64_t kStart = 1403636579763555584;
constexpr std::int64_t kPeriod = 50'000'000;  // 20 Hz
constexpr int kFrames = 4;

std::string sensorYaml(double tx) {
  // A fixed rotation (90 deg about body z) and a translation whose x differs per camera.
  return fmt::format(R"(%YAML:1.0
---
# General sensor definitions.
sensor_type: camera
comment: synthetic cam

# Sensor extrinsics wrt. the body-frame.
T_BS:
  cols: 4
  rows: 4
  data: [0.0, -1.0, 0.0, {},
         1.0, 0.0, 0.0, 0.02,
         0.0, 0.0, 1.0, -0.01,
         0.0, 0.0, 0.0, 1.0]

# Camera specific definitions.
rate_hz: 20
resolution: [64, 48]
camera_model: pinhole
intrinsics: [45.8, 45.7, 36.7, 24.8] #fu, fv, cu, cv
distortion_model: radial-tangential
distortion_coefficients: [-0.28, 0.07, 0.0002, 1.7e-05]
)",
                     tx);
}

SE3d bodyPose(double t) {
  // Moves along world x at 1 m/s while yawing at 0.5 rad/s.
  return {Eigen::Quaterniond(Eigen::AngleAxisd(0.5 * t, Eigen::Vector3d::UnitZ())),
          Eigen::Vector3d(t, 0.5, 1.0)};
}

void writeEuroc(const std::filesystem::path& root) {
  for (const char* cam : {"cam0", "cam1"}) {
    std::string csv = "#timestamp [ns],filename\n";
    for (int i = 0; i < kFrames; ++i) {
      const std::int64_t stamp = kStart + i * kPeriod;
      csv += fmt::format("{},{}.png\n", stamp, stamp);
      const int tag = std::string(cam) == "cam0" ? 10 + i : 100 + i;
      test::writeImage(root / "mav0" / cam / "data" / fmt::format("{}.png", stamp),
                       test::taggedImage(64, 48, CV_8UC1, tag));
    }
    writeText(root / "mav0" / cam / "data.csv", csv);
    writeText(root / "mav0" / cam / "sensor.yaml",
              sensorYaml(std::string(cam) == "cam0" ? -0.02 : 0.09));
  }
  // Ground truth at 200 Hz starting a bit before the first frame, 17 columns like the real files.
  std::string gt =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z [], v..., b_w..., b_a...\n";
  for (int k = -4; k < 4 * 10 + 4; ++k) {
    const std::int64_t stamp = kStart + k * 5'000'000 + 1'000'000;  // offset from the frames
    const SE3d pose = bodyPose(static_cast<double>(stamp - kStart) * 1e-9);
    const auto& q = pose.rotation();
    const auto& p = pose.translation();
    gt += fmt::format(
        "{},{:.12f},{:.12f},{:.12f},{:.12f},{:.12f},{:.12f},{:.12f},0,0,0,0,0,0,0,0,0\n", stamp,
        p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
  }
  writeText(root / "mav0" / "state_groundtruth_estimate0" / "data.csv", gt);
}

TEST(EurocReader, ReadsFramesStereoCameraAndGroundTruth) {
  TempFolder folder;
  writeEuroc(folder.path());
  ASSERT_EQ(detectDatasetFormat(folder.path()), DatasetFormat::kEuroc);
  auto reader = openDataset(folder.path());
  const DatasetInfo& info = reader->info();
  EXPECT_EQ(info.format, DatasetFormat::kEuroc);
  EXPECT_EQ(info.frame_count, static_cast<std::size_t>(kFrames));
  EXPECT_TRUE(info.has_stereo);
  EXPECT_FALSE(info.stereo_rectified);
  EXPECT_FALSE(info.has_depth);
  EXPECT_TRUE(info.has_ground_truth);
  EXPECT_NEAR(info.fps, 20.0, 1e-6);

  const PinholeCamera& camera = reader->camera();
  EXPECT_EQ(camera.width(), 64);
  EXPECT_EQ(camera.height(), 48);
  EXPECT_DOUBLE_EQ(camera.fx(), 45.8);
  EXPECT_DOUBLE_EQ(camera.cy(), 24.8);
  EXPECT_DOUBLE_EQ(camera.intrinsics().distortion.k1, -0.28);
  EXPECT_DOUBLE_EQ(camera.intrinsics().distortion.k3, 0.0);
  EXPECT_NEAR(camera.intrinsics().baseline_m, 0.11, 1e-12);
  EXPECT_EQ(camera.intrinsics().fps, 20.0);

  ASSERT_EQ(reader->timestamps().size(), static_cast<std::size_t>(kFrames));
  EXPECT_NEAR(reader->timestamps()[1] - reader->timestamps()[0], 0.05, 1e-6);
  EXPECT_NEAR(reader->timestamps()[0], 1403636579.763555584, 1e-6);

  Eigen::Matrix4d body_from_camera;
  body_from_camera << 0, -1, 0, -0.02, 1, 0, 0, 0.02, 0, 0, 1, -0.01, 0, 0, 0, 1;
  for (std::size_t i = 0; i < static_cast<std::size_t>(kFrames); ++i) {
    const DatasetFrame frame = reader->load(i);
    EXPECT_EQ(frame.gray.type(), CV_8UC1);
    EXPECT_EQ(frame.gray.at<unsigned char>(0, 0), 10 + i);
    ASSERT_FALSE(frame.right_gray.empty());
    EXPECT_EQ(frame.right_gray.at<unsigned char>(0, 0), 100 + i);
    EXPECT_TRUE(frame.color.empty());
    ASSERT_TRUE(frame.ground_truth);
    const SE3d expected =
        bodyPose(0.05 * static_cast<double>(i)) * SE3d::fromMatrix(body_from_camera);
    EXPECT_NEAR((frame.ground_truth->translation() - expected.translation()).norm(), 0.0, 1e-6);
    EXPECT_NEAR(rotationDistance(*frame.ground_truth, expected), 0.0, 1e-6);
  }
}

TEST(EurocReader, AcceptsTheMav0FolderItselfAndWithoutStereo) {
  TempFolder folder;
  writeEuroc(folder.path());
  std::filesystem::remove_all(folder / "mav0/cam1");
  auto reader = openDataset(folder / "mav0");
  EXPECT_EQ(reader->info().format, DatasetFormat::kEuroc);
  EXPECT_FALSE(reader->info().has_stereo);
  EXPECT_EQ(reader->camera().intrinsics().baseline_m, 0.0);
  EXPECT_TRUE(reader->load(2).right_gray.empty());
}

TEST(EurocReader, MalformedCsvLineIsNamed) {
  TempFolder folder;
  writeEuroc(folder.path());
  writeText(folder / "mav0/cam0/data.csv",
            "#timestamp [ns],filename\n1403636579763555584,a.png\n"
            "14036365797635x5584,b.png\n");
  try {
    openDataset(folder.path());
    FAIL() << "expected an error";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("cam0/data.csv:3"), std::string::npos) << e.what();
  }
}

TEST(EurocReader, ImageSizeDifferentFromSensorYamlIsAnError) {
  TempFolder folder;
  writeEuroc(folder.path());
  const auto stamp = std::to_string(kStart + kPeriod);
  test::writeImage(folder / ("mav0/cam0/data/" + stamp + ".png"),
                   test::taggedImage(32, 48, CV_8UC1, 1));
  auto reader = openDataset(folder.path());
  try {
    reader->load(1);
    FAIL() << "expected an error";
  } catch (const DatasetError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(stamp + ".png"), std::string::npos) << message;
    EXPECT_NE(message.find("32x48"), std::string::npos) << message;
    EXPECT_NE(message.find("64x48"), std::string::npos) << message;
  }
}

}  // namespace
}  // namespace edgeslam
