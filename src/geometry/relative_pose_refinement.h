#pragma once
// Non-linear refinement of a two-view relative pose (5 degrees of freedom: rotation and the
// direction of the baseline) by Levenberg-Marquardt on the Sampson approximation of the
// reprojection error (Hartley-Zisserman 11.4.3). The linear 8-point / DLT estimates are noticeably
// less accurate than this maximum-likelihood approximation.
#include <Eigen/Core>
#include <span>

#include "geometry/se3.h"

namespace edgeslam {

// Sampson distance of one correspondence (normalised image coordinates) under E = [t]x R.
double sampsonDistance(const Eigen::Matrix3d& E21, const Eigen::Vector2d& normalized1,
                       const Eigen::Vector2d& normalized2);

// Refines cam2_from_cam1 on correspondences given in normalised image coordinates; the result has
// |t| = 1. cauchy_scale > 0 (in normalised units, i.e. pixels / focal) makes the cost robust to
// the few outliers an epipolar gate lets through. Returns the initial pose when there are fewer
// than six correspondences or the translation is zero. Throws std::invalid_argument when the
// spans differ in size.
SE3d refineRelativePose(const SE3d& cam2_from_cam1, std::span<const Eigen::Vector2d> normalized1,
                        std::span<const Eigen::Vector2d> normalized2, double cauchy_scale = 0.0,
                        int max_iterations = 15);

}  // namespace edgeslam
