#pragma once
// The pinhole numbers the optimisation problems need: undistorted pixels only, plus bf (focal
// length times baseline) so that a depth d gives the virtual right-image coordinate u - bf / d.
#include <Eigen/Core>

#include "geometry/camera.h"

namespace edgeslam {

struct CameraProjection {
  double fx = 0.0, fy = 0.0, cx = 0.0, cy = 0.0;
  double bf = 0.0;  // 0 when only monocular observations are used

  // bf defaults to fx * baseline_m of the camera; RGB-D callers pass their virtual baseline.
  static CameraProjection fromCamera(const PinholeCamera& camera, double bf = -1.0);
  // Throws std::invalid_argument naming the bad value.
  void validate() const;

  Eigen::Vector2d project(const Eigen::Vector3d& point_camera) const {
    const double inv_z = 1.0 / point_camera.z();
    return {fx * point_camera.x() * inv_z + cx, fy * point_camera.y() * inv_z + cy};
  }
  double rightU(const Eigen::Vector3d& point_camera) const {
    return fx * point_camera.x() / point_camera.z() + cx - bf / point_camera.z();
  }
};

}  // namespace edgeslam
