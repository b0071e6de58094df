#include <gtest/gtest.h>

#include "io/dataset.h"
#include "temp_folder.h"

namespace edgeslam {
namespace {

using test::TempFolder;
using test::writeText;

void writeFolder(const TempFolder& folder) {
  // Natural order: img2 before img10.
  test::writeImage(folder / "img1.png", test::taggedImage(40, 30, CV_8UC3, 1));
  test::writeImage(folder / "img10.png", test::taggedImage(40, 30, CV_8UC3, 3));
  test::writeImage(folder / "img2.png", test::taggedImage(40, 30, CV_8UC3, 2));
  writeText(folder / "notes.txt", "not an image\n");
  writeText(folder / "camera.yaml", test::minimalCameraYaml(40, 30, "fps: 15\n"));
}

TEST(ImageFolderReader, NaturalOrderTimestampsFromFpsAndColour) {
  TempFolder folder;
  writeFolder(folder);
  ASSERT_EQ(detectDatasetFormat(folder.path()), DatasetFormat::kImages);
  auto reader = openDataset(folder.path());
  ASSERT_EQ(reader->info().frame_count, 3u);
  EXPECT_FALSE(reader->info().has_ground_truth);
  EXPECT_NEAR(reader->info().fps, 15.0, 1e-9);
  EXPECT_NEAR(reader->timestamps()[2], 2.0 / 15.0, 1e-12);
  EXPECT_EQ(reader->camera().fx(), 100.0);
  for (std::size_t i = 0; i < 3; ++i) {
    const DatasetFrame frame = reader->load(i);
    ASSERT_EQ(frame.color.type(), CV_8UC3);
    EXPECT_EQ(frame.color.at<cv::Vec3b>(0, 0)[0], i + 1) << frame.name;
    EXPECT_EQ(frame.gray.type(), CV_8UC1);
    EXPECT_EQ(frame.gray.size(), cv::Size(40, 30));
  }
  EXPECT_EQ(reader->load(2).name, "img10.png");
}

TEST(ImageFolderReader, TimesAndGroundTruthFiles) {
  TempFolder folder;
  writeFolder(folder);
  writeText(folder / "times.txt", "10.0\n10.1\n10.2\n");
  writeText(folder / "groundtruth.txt",
            "# t tx ty tz qx qy qz qw\n10.0 0 0 0 0 0 0 1\n10.1 1 0 0 0 0 0 1\n"
            "10.11 2 0 0 0 0 0 1\n");
  auto reader = openDataset(folder.path());
  EXPECT_NEAR(reader->timestamps()[1], 10.1, 1e-12);
  EXPECT_NEAR(reader->info().fps, 10.0, 1e-6);
  ASSERT_TRUE(reader->info().has_ground_truth);
  ASSERT_TRUE(reader->groundTruth()[1]);
  EXPECT_NEAR(reader->groundTruth()[1]->translation().x(), 1.0, 1e-9);
  EXPECT_FALSE(reader->groundTruth()[2]);  // 10.2 is 0.09 s after the last sample
  EXPECT_TRUE(reader->load(0).ground_truth);
}

TEST(ImageFolderReader, CameraOverrideReplacesTheFolderCamera) {
  TempFolder folder;
  writeFolder(folder);
  DatasetOptions options;
  options.format = DatasetFormat::kImages;
  CameraIntrinsics override_camera;
  override_camera.width = 40;
  override_camera.height = 30;
  override_camera.fx = override_camera.fy = 77.0;
  override_camera.cx = 20;
  override_camera.cy = 15;
  options.camera_override = override_camera;
  auto reader = openDataset(folder.path(), options);
  EXPECT_EQ(reader->camera().fx(), 77.0);
  EXPECT_EQ(reader->camera().intrinsics().fps, 15.0);  // kept from camera.yaml
}

TEST(ImageFolderReader, TimesCountMustMatchImages) {
  TempFolder folder;
  writeFolder(folder);
  writeText(folder / "times.txt", "0\n0.1\n");
  try {
    openDataset(folder.path());
    FAIL() << "expected an error";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("times.txt has 2 timestamps but the folder has 3 images"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace edgeslam
