#pragma once
// Distance from a point to a stretch of path walked straight from `a` to `b` (a route's leg, or
// a camera's or the truth's path between two frames).
#include <Eigen/Core>
#include <algorithm>

namespace edgeslam {

inline double distanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                                const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double length2 = ab.squaredNorm();
  const double t = length2 > 0.0 ? std::clamp((p - a).dot(ab) / length2, 0.0, 1.0) : 0.0;
  return (a + t * ab - p).norm();
}

}  // namespace edgeslam
