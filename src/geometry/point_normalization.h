#pragma once
// Isotropic normalisation of 2D points (Hartley): centroid to the origin, mean distance sqrt(2).
// Conditions the DLT systems of the homography and the 8-point algorithm.
#include <Eigen/Core>
#include <vector>

namespace edgeslam {

struct NormalizedPoints {
  std::vector<Eigen::Vector2d> points;
  // Maps an original homogeneous point to its normalised one: x_n = T * x.
  Eigen::Matrix3d T = Eigen::Matrix3d::Identity();
};

// Throws std::invalid_argument when points is empty or all points coincide.
NormalizedPoints normalizePoints(const std::vector<Eigen::Vector2d>& points);

}  // namespace edgeslam
