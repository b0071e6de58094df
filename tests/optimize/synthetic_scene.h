#pragma once
// Small synthetic worlds for the optimisation tests: a camera, random points in front of it, exact
// projections, and pose perturbations of a chosen size.
#include <Eigen/Core>
#include <cmath>
#include <random>

#include "geometry/se3.h"
#include "geometry/so3.h"
#include "optimize/camera_projection.h"

namespace edgeslam::test {

inline CameraProjection testCamera() {
  return {500.0, 500.0, 320.0, 240.0, 40.0};
}

inline double degToRad(double deg) {
  return deg * M_PI / 180.0;
}
inline double radToDeg(double rad) {
  return rad * 180.0 / M_PI;
}

// A point that projects inside a 640x480 image of `T_cw` at a depth in [min_depth, max_depth].
// `half_window` limits the pixel to that distance from the principal point (a narrow view).
inline Eigen::Vector3d randomVisiblePoint(const SE3d& T_cw, std::mt19937& rng,
                                          double min_depth = 2.0, double max_depth = 8.0,
                                          double half_window = 220.0) {
  const CameraProjection cam = testCamera();
  std::uniform_real_distribution<double> u(cam.cx - 1.36 * half_window,
                                           cam.cx + 1.36 * half_window);
  std::uniform_real_distribution<double> v(cam.cy - half_window, cam.cy + half_window);
  std::uniform_real_distribution<double> d(min_depth, max_depth);
  const double depth = d(rng);
  // Drawn last coordinate first, the order these scenes were tuned with (gcc evaluates call
  // arguments right to left, clang left to right): every compiler draws the same scene.
  const double pv = v(rng);
  const double pu = u(rng);
  const Eigen::Vector3d pc((pu - cam.cx) / cam.fx * depth, (pv - cam.cy) / cam.fy * depth, depth);
  return T_cw.inverse() * pc;
}

// Rotation by `angle_rad` about a random axis and translation of `distance` in a random direction,
// applied on the left.
inline SE3d perturb(const SE3d& pose, double distance, double angle_rad, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  const auto draw = [&] {  // last coordinate first, as in randomVisiblePoint
    const double z = n(rng);
    const double y = n(rng);
    const double x = n(rng);
    return Eigen::Vector3d(x, y, z);
  };
  const Eigen::Vector3d axis = draw().normalized();
  const Eigen::Vector3d dir = draw().normalized();
  return SE3d(so3Exp(axis * angle_rad), dir * distance) * pose;
}

inline double translationError(const SE3d& a, const SE3d& b) {
  return (a.inverse().translation() - b.inverse().translation()).norm();
}

}  // namespace edgeslam::test
