#include "io/camera_file.h"

#include <gtest/gtest.h>

#include "io/dataset_error.h"
#include "temp_folder.h"

namespace edgeslam {
namespace {

using test::TempFolder;
using test::writeText;

std::string errorOf(const std::filesystem::path& path) {
  try {
    loadCameraFile(path);
  } catch (const DatasetError& e) {
    return e.what();
  }
  return "no error";
}

TEST(CameraFile, RoundTripKeepsEveryField) {
  TempFolder folder;
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = 520.908620;
  in.fy = 521.007327;
  in.cx = 325.141442;
  in.cy = 249.701764;
  in.distortion = {0.231222, -0.784899, -0.003257, -0.000105, 0.917205};
  in.depth_factor = 5000;
  in.baseline_m = 0.1234567890123;
  in.fps = 29.97;
  saveCameraFile(folder / "sub/cam.yaml", in);
  const CameraIntrinsics out = loadCameraFile(folder / "sub/cam.yaml");
  EXPECT_EQ(out.width, 640);
  EXPECT_EQ(out.height, 480);
  EXPECT_EQ(out.fx, in.fx);
  EXPECT_EQ(out.fy, in.fy);
  EXPECT_EQ(out.cx, in.cx);
  EXPECT_EQ(out.cy, in.cy);
  EXPECT_EQ(out.distortion.k1, in.distortion.k1);
  EXPECT_EQ(out.distortion.k2, in.distortion.k2);
  EXPECT_EQ(out.distortion.p1, in.distortion.p1);
  EXPECT_EQ(out.distortion.p2, in.distortion.p2);
  EXPECT_EQ(out.distortion.k3, in.distortion.k3);
  EXPECT_EQ(out.depth_factor, in.depth_factor);
  EXPECT_EQ(out.baseline_m, in.baseline_m);
  EXPECT_EQ(out.fps, in.fps);
}

TEST(CameraFile, OptionalKeysDefaultToZero) {
  TempFolder folder;
  writeText(folder / "c.yaml", "width: 320\nheight: 240\nfx: 200\nfy: 201\ncx: 160\ncy: 120.5\n");
  const CameraIntrinsics in = loadCameraFile(folder / "c.yaml");
  EXPECT_EQ(in.cy, 120.5);
  EXPECT_TRUE(in.distortion.isZero());
  EXPECT_EQ(in.depth_factor, 0.0);
  EXPECT_EQ(in.baseline_m, 0.0);
  EXPECT_EQ(in.fps, 0.0);
}

TEST(CameraFile, JsonObjectIsAccepted) {
  TempFolder folder;
  writeText(folder / "c.json",
            R"({"width": 64, "height": 48, "fx": 50, "fy": 50, "cx": 32, "cy": 24, "k1": -0.1})");
  const CameraIntrinsics in = loadCameraFile(folder / "c.json");
  EXPECT_EQ(in.width, 64);
  EXPECT_EQ(in.distortion.k1, -0.1);
}

TEST(CameraFile, UnknownKeyIsRejectedNamingKeyFileAndLine) {
  TempFolder folder;
  writeText(folder / "typo.yaml",
            "width: 640\nheight: 480\nfx: 500\nfy: 500\ncx: 320\ncy: 240\ndepth_factr: 5000\n");
  const std::string message = errorOf(folder / "typo.yaml");
  EXPECT_NE(message.find("depth_factr"), std::string::npos) << message;
  EXPECT_NE(message.find("typo.yaml:7"), std::string::npos) << message;
}

TEST(CameraFile, MissingRequiredKeyIsRejected) {
  TempFolder folder;
  writeText(folder / "c.yaml", "width: 640\nheight: 480\nfx: 500\nfy: 500\ncx: 320\n");
  const std::string message = errorOf(folder / "c.yaml");
  EXPECT_NE(message.find("missing required key 'cy'"), std::string::npos) << message;
  EXPECT_NE(message.find("c.yaml"), std::string::npos) << message;
}

TEST(CameraFile, NonNumericValueIsRejected) {
  TempFolder folder;
  writeText(folder / "c.yaml", "width: 640\nheight: 480\nfx: five\nfy: 500\ncx: 320\ncy: 240\n");
  const std::string message = errorOf(folder / "c.yaml");
  EXPECT_NE(message.find("c.yaml:3"), std::string::npos) << message;
  EXPECT_NE(message.find("'fx' must be a number"), std::string::npos) << message;
}

TEST(CameraFile, FractionalWidthAndNonsenseIntrinsicsAreRejected) {
  TempFolder folder;
  writeText(folder / "w.yaml", "width: 640.5\nheight: 480\nfx: 5\nfy: 5\ncx: 3\ncy: 2\n");
  EXPECT_NE(errorOf(folder / "w.yaml").find("whole number"), std::string::npos);
  writeText(folder / "f.yaml", "width: 640\nheight: 480\nfx: -5\nfy: 5\ncx: 3\ncy: 2\n");
  EXPECT_NE(errorOf(folder / "f.yaml").find("fx must be positive"), std::string::npos);
  writeText(folder / "list.yaml", "width: 640\nheight: 480\nfx: [5]\nfy: 5\ncx: 3\ncy: 2\n");
  EXPECT_NE(errorOf(folder / "list.yaml").find("'fx' must be a number"), std::string::npos);
}

TEST(CameraFile, NotYamlOrNotAMappingOrAbsentIsAnError) {
  TempFolder folder;
  writeText(folder / "bad.yaml", "width: [640\n");
  EXPECT_NE(errorOf(folder / "bad.yaml").find("not valid YAML"), std::string::npos);
  writeText(folder / "list.yaml", "- 1\n- 2\n");
  EXPECT_NE(errorOf(folder / "list.yaml").find("mapping"), std::string::npos);
  EXPECT_NE(errorOf(folder / "absent.yaml").find("not found"), std::string::npos);
}

class ShippedCameraFile : public ::testing::TestWithParam<const char*> {};

TEST_P(ShippedCameraFile, LoadsAndStartsWithItsSource) {
  const auto path = std::filesystem::path(EDGESLAM_SOURCE_DIR) / "config/cameras" / GetParam();
  const CameraIntrinsics in = loadCameraFile(path);
  EXPECT_GT(in.fx, 0.0);
  std::ifstream file(path);
  std::string first_line;
  std::getline(file, first_line);
  EXPECT_TRUE(first_line.starts_with("#")) << path << " should say where its numbers come from";
}

INSTANTIATE_TEST_SUITE_P(Config, ShippedCameraFile,
                         ::testing::Values("7scenes.yaml", "kitti07.yaml", "tum-fr1.yaml",
                                           "tum-fr2.yaml", "tum-fr3.yaml"));

TEST(ShippedCameraFiles, HoldTheDocumentedValues) {
  const auto dir = std::filesystem::path(EDGESLAM_SOURCE_DIR) / "config/cameras";
  const CameraIntrinsics seven = loadCameraFile(dir / "7scenes.yaml");
  EXPECT_EQ(seven.fx, 585.0);
  EXPECT_EQ(seven.width, 640);
  EXPECT_EQ(seven.depth_factor, 1000.0);
  const CameraIntrinsics kitti = loadCameraFile(dir / "kitti07.yaml");
  EXPECT_EQ(kitti.fx, 707.0912);
  EXPECT_EQ(kitti.width, 1226);
  EXPECT_EQ(kitti.height, 370);
  EXPECT_NEAR(kitti.baseline_m, 379.8145 / 707.0912, 1e-9);
  EXPECT_EQ(kitti.fps, 10.0);
  const CameraIntrinsics fr2 = loadCameraFile(dir / "tum-fr2.yaml");
  EXPECT_EQ(fr2.fx, 520.908620);
  EXPECT_EQ(fr2.distortion.k3, 0.917205);
  EXPECT_EQ(fr2.depth_factor, 5000.0);
  const CameraIntrinsics fr3 = loadCameraFile(dir / "tum-fr3.yaml");
  EXPECT_EQ(fr3.fx, 535.4);
  EXPECT_TRUE(fr3.distortion.isZero());
}

}  // namespace
}  // namespace edgeslam
