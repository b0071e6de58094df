// Bad input gives a DatasetError naming the file (and line), never a crash or silent garbage.
#include <gtest/gtest.h>

#include <functional>

#include "io/dataset.h"
#include "temp_folder.h"

namespace edgeslam {
namespace {

using test::TempFolder;
using test::writeText;

std::string errorOf(const std::function<void()>& action) {
  try {
    action();
  } catch (const DatasetError& e) {
    return e.what();
  }
  return "no error";
}

// A valid 3-frame TUM folder with camera.yaml and ground truth.
void writeTum(const TempFolder& folder) {
  writeText(folder / "rgb.txt", "# rgb\n1.0 rgb/1.png\n1.1 rgb/2.png\n1.2 rgb/3.png\n");
  for (const char* name : {"rgb/1.png", "rgb/2.png", "rgb/3.png"}) {
    test::writeImage(folder / name, test::taggedImage(32, 24, CV_8UC3, 1));
  }
  writeText(folder / "camera.yaml", test::minimalCameraYaml(32, 24));
  writeText(folder / "groundtruth.txt", "1.0 0 0 0 0 0 0 1\n1.2 1 0 0 0 0 0 1\n");
}

TEST(DatasetErrors, MalformedLineNamesFileAndLine) {
  TempFolder folder;
  writeTum(folder);
  writeText(folder / "rgb.txt", "# rgb\n1.0 rgb/1.png\n1.1x rgb/2.png\n");
  std::string message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("rgb.txt:3"), std::string::npos) << message;
  EXPECT_NE(message.find("1.1x"), std::string::npos) << message;

  writeText(folder / "rgb.txt", "1.0 rgb/1.png\n1.1\n");
  message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("rgb.txt:2"), std::string::npos) << message;

  writeTum(folder);
  writeText(folder / "groundtruth.txt", "# gt\n1.0 0 0 0 0 0 0 1\n1.2 1 0 0 0 0 1\n");
  message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("groundtruth.txt:3"), std::string::npos) << message;
}

TEST(DatasetErrors, KittiMalformedTimesAndCalibration) {
  TempFolder folder;
  test::writeImage(folder / "image_0/000000.png", test::taggedImage(20, 10, CV_8UC1, 0));
  test::writeImage(folder / "image_0/000001.png", test::taggedImage(20, 10, CV_8UC1, 0));
  writeText(folder / "calib.txt", "P0: 50 0 10 0 0 50 5 0 0 0 1 0\n");
  writeText(folder / "times.txt", "0.0\nzero point one\n");
  std::string message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("times.txt:2"), std::string::npos) << message;

  writeText(folder / "times.txt", "0.0\n0.1\n");
  writeText(folder / "calib.txt", "P0: 50 0 10 0 0 50 5 0 0 0 1\n");
  message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("calib.txt:1"), std::string::npos) << message;

  writeText(folder / "calib.txt", "P0: 50 0 10 0 0 50 5 0 0 0 1 0\n");
  writeText(folder / "times.txt", "0.0\n");
  message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("no timestamp for 000001.png"), std::string::npos) << message;
}

TEST(DatasetErrors, MissingCameraTellsTheUserToPassOne) {
  TempFolder folder;
  test::writeImage(folder / "a.png", test::taggedImage(20, 10, CV_8UC1, 0));
  const std::string message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("--camera"), std::string::npos) << message;
  EXPECT_NE(message.find("camera.yaml"), std::string::npos) << message;
}

TEST(DatasetErrors, ImageSizeDifferentFromTheCamera) {
  TempFolder folder;
  writeTum(folder);
  writeText(folder / "camera.yaml", test::minimalCameraYaml(64, 48));
  std::string message = errorOf([&] { openDataset(folder.path()); });
  EXPECT_NE(message.find("1.png"), std::string::npos) << message;
  EXPECT_NE(message.find("32x24"), std::string::npos) << message;
  EXPECT_NE(message.find("64x48"), std::string::npos) << message;

  // A later frame of another size is caught when it is loaded.
  writeTum(folder);
  test::writeImage(folder / "rgb/3.png", test::taggedImage(30, 24, CV_8UC3, 1));
  auto reader = openDataset(folder.path());
  EXPECT_NO_THROW(reader->load(1));
  message = errorOf([&] { reader->load(2); });
  EXPECT_NE(message.find("3.png"), std::string::npos) << message;
  EXPECT_NE(message.find("30x24"), std::string::npos) << message;
}

TEST(DatasetErrors, CameraOverrideOfAnotherSizeIsRejected) {
  TempFolder folder;
  writeTum(folder);
  DatasetOptions options;
  CameraIntrinsics wrong;
  wrong.width = 640;
  wrong.height = 480;
  wrong.fx = wrong.fy = 500;
  wrong.cx = 320;
  wrong.cy = 240;
  options.camera_override = wrong;
  const std::string message = errorOf([&] { openDataset(folder.path(), options); });
  EXPECT_NE(message.find("--camera"), std::string::npos) << message;
  EXPECT_NE(message.find("640x480"), std::string::npos) << message;
}

TEST(DatasetErrors, UndecodableAndMissingImages) {
  TempFolder folder;
  writeTum(folder);
  writeText(folder / "rgb/2.png", "garbage, not a png");
  auto reader = openDataset(folder.path());
  std::string message = errorOf([&] { reader->load(1); });
  EXPECT_NE(message.find("cannot decode"), std::string::npos) << message;
  EXPECT_NE(message.find("2.png"), std::string::npos) << message;

  std::filesystem::remove(folder / "rgb/3.png");
  message = errorOf([&] { reader->load(2); });
  EXPECT_NE(message.find("not found"), std::string::npos) << message;
  EXPECT_NE(message.find("3.png"), std::string::npos) << message;
  EXPECT_THROW(reader->load(3), DatasetError);  // past the end
}

TEST(DatasetErrors, DepthSizeDifferentFromTheImage) {
  TempFolder folder;
  writeTum(folder);
  writeText(folder / "depth.txt", "1.0 depth/1.png\n1.1 depth/2.png\n1.2 depth/3.png\n");
  for (const char* name : {"depth/1.png", "depth/2.png", "depth/3.png"}) {
    test::writeImage(folder / name, cv::Mat(12, 16, CV_16UC1, cv::Scalar(1000)));
  }
  auto reader = openDataset(folder.path());
  const std::string message = errorOf([&] { reader->load(0); });
  EXPECT_NE(message.find("depth/1.png"), std::string::npos) << message;
  EXPECT_NE(message.find("16x12"), std::string::npos) << message;

  test::writeImage(folder / "depth/2.png", cv::Mat(24, 32, CV_8UC1, cv::Scalar(10)));
  EXPECT_NE(errorOf([&] { reader->load(1); }).find("16-bit"), std::string::npos);
}

TEST(DatasetErrors, DetectionSaysWhatItLookedFor) {
  TempFolder folder;
  writeText(folder / "readme.txt", "nothing here\n");
  const std::string message = errorOf([&] { detectDatasetFormat(folder.path()); });
  for (const char* looked_for :
       {"rgb.txt", "times.txt", "mav0/cam0/data.csv", "frame-NNNNNN", "png", "--format"}) {
    EXPECT_NE(message.find(looked_for), std::string::npos) << looked_for << " in " << message;
  }
  EXPECT_NE(errorOf([&] { openDataset(folder / "absent"); }).find("not found"), std::string::npos);
  // An explicit format on the wrong folder fails with that format's own complaint.
  DatasetOptions kitti;
  kitti.format = DatasetFormat::kKitti;
  EXPECT_NE(errorOf([&] { openDataset(folder.path(), kitti); }).find("image_0"), std::string::npos);
}

TEST(DatasetFormatNames, RoundTripAndRejectUnknown) {
  for (const char* name : {"auto", "tum", "kitti", "euroc", "7scenes", "images", "video"}) {
    EXPECT_EQ(toString(parseDatasetFormat(name)), name);
  }
  EXPECT_THROW(parseDatasetFormat("TUM-RGBD"), std::invalid_argument);
}

TEST(DatasetOverride, KeepsTheDatasetsDepthFactorWhenTheOverrideHasNone) {
  TempFolder folder;
  writeTum(folder);
  writeText(folder / "camera.yaml", test::minimalCameraYaml(32, 24, "depth_factor: 1000\n"));
  DatasetOptions options;
  CameraIntrinsics other;
  other.width = 32;
  other.height = 24;
  other.fx = other.fy = 42;
  other.cx = 16;
  other.cy = 12;
  options.camera_override = other;
  auto reader = openDataset(folder.path(), options);
  EXPECT_EQ(reader->camera().fx(), 42.0);
  EXPECT_EQ(reader->camera().intrinsics().depth_factor, 1000.0);
}

}  // namespace
}  // namespace edgeslam
