#pragma once
// Pinhole camera with radial-tangential (Brown-Conrady / OpenCV) distortion, optional stereo
// baseline.
#include <Eigen/Core>
#include <opencv2/core.hpp>
#include <optional>
#include <string>
#include <vector>

namespace edgeslam {

struct Distortion {
  double k1 = 0.0, k2 = 0.0, p1 = 0.0, p2 = 0.0, k3 = 0.0;
  bool isZero() const { return k1 == 0.0 && k2 == 0.0 && p1 == 0.0 && p2 == 0.0 && k3 == 0.0; }
};

struct CameraIntrinsics {
  int width = 0;
  int height = 0;
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  Distortion distortion;
  double baseline_m = 0.0;    // stereo baseline, 0 when monocular
  double depth_factor = 0.0;  // depth-image units per metre, 0 when no depth
  double fps = 0.0;           // nominal frame rate, 0 when unknown
};

class PinholeCamera {
 public:
  PinholeCamera() = default;
  // Throws std::invalid_argument naming the bad field when the intrinsics make no sense.
  explicit PinholeCamera(const CameraIntrinsics& intrinsics);

  const CameraIntrinsics& intrinsics() const { return intrinsics_; }
  int width() const { return intrinsics_.width; }
  int height() const { return intrinsics_.height; }
  double fx() const { return intrinsics_.fx; }
  double fy() const { return intrinsics_.fy; }
  double cx() const { return intrinsics_.cx; }
  double cy() const { return intrinsics_.cy; }
  bool hasDistortion() const { return !intrinsics_.distortion.isZero(); }
  Eigen::Matrix3d K() const;
  cv::Mat cvK() const;
  cv::Mat cvDistortion() const;

  // Ideal (undistorted) pinhole projection of a point in the camera frame; nullopt behind the
  // camera.
  std::optional<Eigen::Vector2d> project(const Eigen::Vector3d& point_camera) const;
  // Projection through the distortion model, i.e. where the point lands in the raw image.
  std::optional<Eigen::Vector2d> projectDistorted(const Eigen::Vector3d& point_camera) const;
  // Ray through an undistorted pixel, normalised so that z = 1.
  Eigen::Vector3d unproject(const Eigen::Vector2d& undistorted_pixel) const;
  // Applies the distortion model to an undistorted pixel.
  Eigen::Vector2d distort(const Eigen::Vector2d& undistorted_pixel) const;
  // Removes distortion from raw pixels (iterative inverse, converged to ~1e-6 px).
  Eigen::Vector2d undistort(const Eigen::Vector2d& distorted_pixel) const;
  std::vector<cv::Point2f> undistort(const std::vector<cv::Point2f>& distorted_pixels) const;

  // Bounds of the undistorted image (the corners mapped through undistort): where keypoints can
  // land.
  struct Bounds {
    double min_x, max_x, min_y, max_y;
  };
  Bounds undistortedBounds() const { return bounds_; }
  bool isInImage(const Eigen::Vector2d& undistorted_pixel) const;

  std::string describe() const;

 private:
  CameraIntrinsics intrinsics_;
  Bounds bounds_{0, 0, 0, 0};
};

}  // namespace edgeslam
