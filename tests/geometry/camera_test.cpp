#include "geometry/camera.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>

namespace edgeslam {
namespace {

CameraIntrinsics fr2() {
  // TUM Freiburg 2, a real camera with strong radial distortion.
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = 520.9086;
  in.fy = 521.0073;
  in.cx = 325.1414;
  in.cy = 249.7018;
  in.distortion = {0.231222, -0.784899, -0.003257, -0.000105, 0.917205};
  return in;
}

TEST(PinholeCamera, ProjectUnprojectRoundTrip) {
  const PinholeCamera cam(fr2());
  const Eigen::Vector3d p(0.3, -0.2, 2.0);
  const auto px = cam.project(p);
  ASSERT_TRUE(px.has_value());
  const Eigen::Vector3d ray = cam.unproject(*px);
  EXPECT_LT((ray * p.z() - p).norm(), 1e-12);
}

TEST(PinholeCamera, KnownProjection) {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = 585.0;
  in.cx = 320.0;
  in.cy = 240.0;
  const PinholeCamera cam(in);
  const auto px = cam.project(Eigen::Vector3d(1.0, 0.5, 2.0));
  ASSERT_TRUE(px.has_value());
  EXPECT_DOUBLE_EQ(px->x(), 320.0 + 585.0 * 0.5);
  EXPECT_DOUBLE_EQ(px->y(), 240.0 + 585.0 * 0.25);
  EXPECT_FALSE(cam.project(Eigen::Vector3d(0.0, 0.0, -1.0)).has_value());
}

TEST(PinholeCamera, DistortUndistortRoundTripAcrossImage) {
  const PinholeCamera cam(fr2());
  double worst = 0.0;
  for (int y = 10; y < 480; y += 47) {
    for (int x = 10; x < 640; x += 53) {
      const Eigen::Vector2d raw(x, y);
      const Eigen::Vector2d back = cam.distort(cam.undistort(raw));
      worst = std::max(worst, (back - raw).norm());
    }
  }
  EXPECT_LT(worst, 1e-3);
}

TEST(PinholeCamera, UndistortMatchesOpenCvProjection) {
  const PinholeCamera cam(fr2());
  const Eigen::Vector3d p(-0.4, 0.3, 1.5);
  const auto raw = cam.projectDistorted(p);
  ASSERT_TRUE(raw.has_value());
  std::vector<cv::Point3d> obj{{p.x(), p.y(), p.z()}};
  std::vector<cv::Point2d> img;
  cv::projectPoints(obj, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cam.cvK(), cam.cvDistortion(),
                    img);
  EXPECT_NEAR(raw->x(), img[0].x, 1e-9);
  EXPECT_NEAR(raw->y(), img[0].y, 1e-9);
  EXPECT_LT((cam.undistort(*raw) - *cam.project(p)).norm(), 1e-3);
}

TEST(PinholeCamera, UndistortedBoundsContainCentre) {
  const PinholeCamera cam(fr2());
  const auto b = cam.undistortedBounds();
  EXPECT_LT(b.min_x, 325.0);
  EXPECT_GT(b.max_x, 325.0);
  EXPECT_TRUE(cam.isInImage({325.0, 250.0}));
}

TEST(PinholeCamera, RejectsBadIntrinsics) {
  CameraIntrinsics in = fr2();
  in.fx = 0.0;
  EXPECT_THROW(PinholeCamera{in}, std::invalid_argument);
  in = fr2();
  in.width = -1;
  EXPECT_THROW(PinholeCamera{in}, std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
