#pragma once
// Small synthetic trajectories with analytically known errors, shared by the eval tests.
#include <Eigen/Geometry>
#include <cmath>

#include "eval/association.h"
#include "io/trajectory.h"

namespace edgeslam::test {

inline SE3d yaw(double angle, const Eigen::Vector3d& t = Eigen::Vector3d::Zero()) {
  return {Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitY())), t};
}

// A wavy 3D path (not planar, so alignments are well determined), stamped every `dt` seconds.
inline Trajectory wavyTrajectory(std::size_t n, double dt = 0.1) {
  Trajectory t;
  for (std::size_t i = 0; i < n; ++i) {
    const double s = static_cast<double>(i);
    const Eigen::Vector3d p(0.3 * s, 2.0 * std::sin(0.11 * s), 1.5 * std::cos(0.07 * s) + 0.02 * s);
    t.push_back({dt * s, yaw(0.05 * s, p)});
  }
  return t;
}

// Pairs i <-> i of two equally long pose lists.
inline PosePairs pairsOf(const Trajectory& gt, const Trajectory& est) {
  return associateByIndex(gt, est);
}

}  // namespace edgeslam::test
