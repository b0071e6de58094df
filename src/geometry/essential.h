#pragma once
// Essential matrix E = K2^T F K1 and its four motion hypotheses (Hartley-Zisserman 9.6.2).
#include <Eigen/Core>
#include <array>

#include "geometry/se3.h"

namespace edgeslam {

Eigen::Matrix3d essentialFromFundamental(const Eigen::Matrix3d& F21, const Eigen::Matrix3d& K1,
                                         const Eigen::Matrix3d& K2);

// The four (R, t) with E ~ [t]x R, as cam2_from_cam1 with |t| = 1. Exactly one puts the scene in
// front of both cameras; the caller decides by triangulating.
std::array<SE3d, 4> decomposeEssential(const Eigen::Matrix3d& E21);

}  // namespace edgeslam
