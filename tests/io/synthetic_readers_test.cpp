// TUM, KITTI and 7-Scenes readers on tiny synthetic folders: the cases the shared data lacks
// (depth association, stereo, official KITTI layout, invalid depth and poses).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include "io/dataset.h"
#include "temp_folder.h"

namespace edgeslam {
namespace {

using test::TempFolder;
using test::writeText;

cv::Mat constantDepth(int width, int height, std::uint16_t value) {
  return cv::Mat(height, width, CV_16UC1, cv::Scalar(value));
}

TEST(TumReader, AssociatesDepthWithinTwentyMillisecondsAndDropsFramesWithout) {
  TempFolder folder;
  std::string rgb = "# color images\n", depth = "# depth\n";
  const double rgb_times[] = {100.000, 100.033, 100.066, 100.100};
  const double depth_times[] = {100.001, 100.034, 100.110};  // none near 100.066
  for (int i = 0; i < 4; ++i) {
    const auto name = fmt::format("rgb/{:.6f}.png", rgb_times[i]);
    rgb += fmt::format("{:.6f} {}\n", rgb_times[i], name);
    test::writeImage(folder / name, test::taggedImage(32, 24, CV_8UC3, i));
  }
  for (int i = 0; i < 3; ++i) {
    const auto name = fmt::format("depth/{:.6f}.png", depth_times[i]);
    depth += fmt::format("{:.6f} {}\n", depth_times[i], name);
    test::writeImage(folder / name,
                     constantDepth(32, 24, static_cast<std::uint16_t>(5000 * (i + 1))));
  }
  writeText(folder / "rgb.txt", rgb);
  writeText(folder / "depth.txt", depth);
  writeText(folder / "camera.yaml", test::minimalCameraYaml(32, 24));

  auto reader = openDataset(folder.path());
  EXPECT_EQ(reader->info().format, DatasetFormat::kTum);
  ASSERT_EQ(reader->info().frame_count, 3u);
  EXPECT_TRUE(reader->info().has_depth);
  EXPECT_EQ(reader->camera().intrinsics().depth_factor, 5000.0);  // TUM default
  EXPECT_NEAR(reader->timestamps()[2], 100.100, 1e-9);
  const double expected_metres[] = {1.0, 2.0, 3.0};
  for (std::size_t i = 0; i < 3; ++i) {
    const DatasetFrame frame = reader->load(i);
    ASSERT_EQ(frame.depth.type(), CV_32FC1);
    EXPECT_FLOAT_EQ(frame.depth.at<float>(5, 5), expected_metres[i]) << i;
  }
  EXPECT_EQ(reader->load(2).color.at<cv::Vec3b>(0, 0)[0], 3);  // the 100.066 frame was dropped
}

TEST(TumReader, RecognisesFreiburgCamerasFromFolderNameOrReadme) {
  TempFolder parent;
  const auto folder = parent / "rgbd_dataset_freiburg1_xyz";
  writeText(folder / "rgb.txt", "1.0 rgb/a.png\n");
  test::writeImage(folder / "rgb/a.png", test::taggedImage(640, 480, CV_8UC3, 0));
  auto fr1 = openDataset(folder);
  EXPECT_DOUBLE_EQ(fr1->camera().fx(), 517.306408);
  EXPECT_DOUBLE_EQ(fr1->camera().intrinsics().distortion.k3, 1.163314);

  const auto plain = parent / "my_recording";
  std::filesystem::create_directories(plain);
  std::filesystem::copy(folder, plain, std::filesystem::copy_options::recursive);
  try {
    openDataset(plain);
    FAIL() << "expected an error: no camera hint";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("--camera"), std::string::npos) << e.what();
  }
  writeText(plain / "README.md", "Recorded with the Freiburg 3 setup: freiburg3 Asus Xtion.\n");
  EXPECT_DOUBLE_EQ(openDataset(plain)->camera().fx(), 535.4);
}

void writeKitti(const std::filesystem::path& folder, bool stereo) {
  std::string times;
  for (int i = 0; i < 3; ++i) {
    test::writeImage(folder / fmt::format("image_0/{:06d}.png", i),
                     test::taggedImage(60, 20, CV_8UC1, i));
    if (stereo) {
      test::writeImage(folder / fmt::format("image_1/{:06d}.png", i),
                       test::taggedImage(60, 20, CV_8UC1, 50 + i));
    }
    times += fmt::format("{:e}\n", 0.1 * i);
  }
  writeText(folder / "times.txt", times);
  writeText(folder / "calib.txt",
            "P0: 50 0 30 0 0 51 10 0 0 0 1 0\nP1: 50 0 30 -25 0 51 10 0 0 0 1 0\n"
            "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
}

TEST(KittiReader, StereoAndGroundTruthFromTheOfficialLayout) {
  TempFolder root;
  const auto sequence = root / "dataset/sequences/05";
  writeKitti(sequence, true);
  writeText(root / "dataset/poses/05.txt",
            "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0.5 0 1 0 0 0 0 1 1\n1 0 0 1 0 1 0 0 0 0 1 2\n"
            "1 0 0 1.5 0 1 0 0 0 0 1 3\n");
  auto reader = openDataset(sequence);
  EXPECT_EQ(reader->info().format, DatasetFormat::kKitti);
  EXPECT_TRUE(reader->info().has_stereo);
  EXPECT_TRUE(reader->info().stereo_rectified);
  EXPECT_DOUBLE_EQ(reader->camera().intrinsics().baseline_m, 0.5);
  EXPECT_DOUBLE_EQ(reader->camera().fy(), 51.0);
  EXPECT_NEAR(reader->info().fps, 10.0, 1e-9);
  ASSERT_EQ(reader->info().frame_count, 3u);  // the 4th pose belongs to frames not present
  ASSERT_TRUE(reader->groundTruth()[2]);
  EXPECT_DOUBLE_EQ(reader->groundTruth()[2]->translation().z(), 2.0);
  const DatasetFrame frame = reader->load(1);
  EXPECT_EQ(frame.gray.at<unsigned char>(0, 0), 1);
  EXPECT_EQ(frame.right_gray.at<unsigned char>(0, 0), 51);
}

TEST(KittiReader, FewerPosesThanFramesIsAnError) {
  TempFolder folder;
  writeKitti(folder.path(), false);
  writeText(folder / "poses.txt", "1 0 0 0 0 1 0 0 0 0 1 0\n");
  try {
    openDataset(folder.path());
    FAIL() << "expected an error";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("poses.txt has 1 poses, none for 000001.png"),
              std::string::npos)
        << e.what();
  }
}

TEST(KittiReader, AnExcerptTakesItsLinesOfTimesAndPoses) {
  TempFolder folder;
  writeKitti(folder.path(), false);
  std::filesystem::rename(folder / "image_0/000000.png", folder / "image_0/000003.png");
  writeText(folder / "times.txt", "0\n0.1\n0.2\n0.3\n0.4\n");
  std::string poses;
  for (int i = 0; i < 5; ++i) poses += fmt::format("1 0 0 {} 0 1 0 0 0 0 1 0\n", i);
  writeText(folder / "poses.txt", poses);
  auto reader = openDataset(folder.path());
  ASSERT_EQ(reader->info().frame_count, 3u);  // 000001, 000002, 000003
  EXPECT_DOUBLE_EQ(reader->timestamps()[2], 0.3);
  EXPECT_DOUBLE_EQ(reader->groundTruth()[2]->translation().x(), 3.0);
  EXPECT_EQ(reader->load(2).name, "000003.png");

  writeText(folder / "times.txt", "0\n0.1\n0.2\n");
  try {
    openDataset(folder.path());
    FAIL() << "expected an error";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("no timestamp for 000003.png"), std::string::npos)
        << e.what();
  }
}

TEST(SevenScenesReader, InvalidDepthBecomesZeroAndInfinitePoseMeansNoGroundTruth) {
  TempFolder folder;
  for (int i = 0; i < 2; ++i) {
    test::writeImage(folder / fmt::format("frame-{:06d}.color.png", i),
                     test::taggedImage(640, 480, CV_8UC3, i));
    cv::Mat depth = constantDepth(640, 480, 1500);
    depth.at<std::uint16_t>(10, 20) = 65535;
    test::writeImage(folder / fmt::format("frame-{:06d}.depth.png", i), depth);
  }
  writeText(folder / "frame-000000.pose.txt", "1 0 0 0.5\n0 1 0 0\n0 0 1 0\n0 0 0 1\n");
  writeText(folder / "frame-000001.pose.txt",
            "-inf -inf -inf -inf\n-inf -inf -inf -inf\n-inf -inf -inf -inf\n0 0 0 1\n");
  auto reader = openDataset(folder.path());
  EXPECT_EQ(reader->info().format, DatasetFormat::kSevenScenes);
  EXPECT_EQ(reader->camera().fx(), 585.0);  // published value when camera-intrinsics.txt is absent
  ASSERT_TRUE(reader->groundTruth()[0]);
  EXPECT_FALSE(reader->groundTruth()[1]);
  const DatasetFrame frame = reader->load(1);
  EXPECT_FLOAT_EQ(frame.depth.at<float>(0, 0), 1.5f);
  EXPECT_FLOAT_EQ(frame.depth.at<float>(10, 20), 0.0f);
  EXPECT_NEAR(frame.timestamp, 1.0 / 30.0, 1e-12);
}

}  // namespace
}  // namespace edgeslam
