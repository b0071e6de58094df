#pragma once
// Whitened reprojection residuals of one keypoint observation, shared by the pose-only and the
// bundle-adjustment problems: 2 components (u, v) for monocular keypoints, 3 (u, v, u_right) when
// the keypoint has a right-image coordinate from stereo matching or a depth image.
#include <Eigen/Core>
#include <limits>

#include "optimize/camera_projection.h"

namespace edgeslam {

inline constexpr int kMonoResiduals = 2;
inline constexpr int kStereoResiduals = 3;
// Points closer than this in front of the camera have no usable projection.
inline constexpr double kMinProjectionDepth = 1e-6;

struct PixelMeasurement {
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted
  double right_u = 0.0;                             // read by stereo residuals only
  double sqrt_information = 1.0;                    // 1 / sigma of the keypoint's pyramid level
};

// residual = sqrt_information * (projection - measurement); optionally d residual / d p_camera.
// Returns false (residual untouched) when the point is not in front of the camera.
template <int kResiduals>
bool whitenedReprojection(const CameraProjection& camera, const Eigen::Vector3d& p,
                          const PixelMeasurement& measurement, double* residual,
                          Eigen::Matrix<double, kResiduals, 3>* d_residual_d_point) {
  static_assert(kResiduals == kMonoResiduals || kResiduals == kStereoResiduals);
  if (!(p.z() > kMinProjectionDepth)) return false;
  const double inv_z = 1.0 / p.z();
  const double u = camera.fx * p.x() * inv_z + camera.cx;
  const double v = camera.fy * p.y() * inv_z + camera.cy;
  const double w = measurement.sqrt_information;
  residual[0] = w * (u - measurement.pixel.x());
  residual[1] = w * (v - measurement.pixel.y());
  if constexpr (kResiduals == kStereoResiduals) {
    residual[2] = w * (u - camera.bf * inv_z - measurement.right_u);
  }
  if (d_residual_d_point != nullptr) {
    const double inv_z2 = inv_z * inv_z;
    auto& j = *d_residual_d_point;
    j(0, 0) = w * camera.fx * inv_z;
    j(0, 1) = 0.0;
    j(0, 2) = -w * camera.fx * p.x() * inv_z2;
    j(1, 0) = 0.0;
    j(1, 1) = w * camera.fy * inv_z;
    j(1, 2) = -w * camera.fy * p.y() * inv_z2;
    if constexpr (kResiduals == kStereoResiduals) {
      j(2, 0) = j(0, 0);
      j(2, 1) = 0.0;
      j(2, 2) = j(0, 2) + w * camera.bf * inv_z2;
    }
  }
  return true;
}

// Squared whitened error (the chi-square statistic); infinity for points not in front.
template <int kResiduals>
double reprojectionChi2(const CameraProjection& camera, const Eigen::Vector3d& point_camera,
                        const PixelMeasurement& measurement) {
  Eigen::Matrix<double, kResiduals, 1> r;
  if (!whitenedReprojection<kResiduals>(camera, point_camera, measurement, r.data(), nullptr)) {
    return std::numeric_limits<double>::infinity();
  }
  return r.squaredNorm();
}

// d p_camera / d delta for the left update T <- exp(delta) T, delta = [rho; phi]: [I, -[p]x].
inline Eigen::Matrix<double, 3, 6> pointJacobianWrtLeftPose(const Eigen::Vector3d& p) {
  Eigen::Matrix<double, 3, 6> j;
  j << 1.0, 0.0, 0.0, 0.0, p.z(), -p.y(),  //
      0.0, 1.0, 0.0, -p.z(), 0.0, p.x(),   //
      0.0, 0.0, 1.0, p.y(), -p.x(), 0.0;
  return j;
}

}  // namespace edgeslam
