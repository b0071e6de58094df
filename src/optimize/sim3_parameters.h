#pragma once
// Sim3 transforms as Ceres parameter blocks for automatic differentiation: a unit quaternion
// (4, Eigen order x y z w, on ceres::EigenQuaternionManifold), a translation (3) and the log of the
// scale (1, held constant for a rigid / fixed-scale problem). x -> e^log_s R x + t.
#include <ceres/rotation.h>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <cmath>

#include "geometry/sim3.h"

namespace edgeslam {

struct Sim3Blocks {
  std::array<double, 4> rotation{0.0, 0.0, 0.0, 1.0};
  std::array<double, 3> translation{0.0, 0.0, 0.0};
  double log_scale = 0.0;

  static Sim3Blocks from(const Sim3d& s) {
    const Eigen::Quaterniond& q = s.rotation();
    return {{q.x(), q.y(), q.z(), q.w()},
            {s.translation().x(), s.translation().y(), s.translation().z()},
            std::log(s.scale())};
  }
  Sim3d toSim3() const {
    return {std::exp(log_scale),
            Eigen::Quaterniond(rotation[3], rotation[0], rotation[1], rotation[2]),
            Eigen::Vector3d(translation[0], translation[1], translation[2])};
  }
};

// The same transform on any scalar type (double or ceres::Jet).
template <typename T>
struct Sim3T {
  Eigen::Quaternion<T> q;
  Eigen::Matrix<T, 3, 1> t;
  T log_s;

  static Sim3T fromBlocks(const T* rotation, const T* translation, const T* log_scale) {
    return {Eigen::Quaternion<T>(rotation[3], rotation[0], rotation[1], rotation[2]),
            Eigen::Matrix<T, 3, 1>(translation[0], translation[1], translation[2]), log_scale[0]};
  }
  static Sim3T fromSim3(const Sim3d& s) {
    return {s.rotation().template cast<T>(), s.translation().template cast<T>(),
            T(std::log(s.scale()))};
  }

  Eigen::Matrix<T, 3, 1> operator*(const Eigen::Matrix<T, 3, 1>& p) const {
    using std::exp;
    return exp(log_s) * (q * p) + t;
  }
  Sim3T operator*(const Sim3T& o) const {
    using std::exp;
    return {q * o.q, exp(log_s) * (q * o.t) + t, log_s + o.log_s};
  }
  Sim3T inverse() const {
    using std::exp;
    const Eigen::Quaternion<T> q_inv = q.conjugate();
    return {q_inv, -exp(-log_s) * (q_inv * t), -log_s};
  }

  // [translation; rotation vector; log scale]: zero exactly at the identity, and a local chart
  // around it (the translation is taken as is rather than through the Sim3 logarithm's W^-1).
  Eigen::Matrix<T, 7, 1> errorVector() const {
    Eigen::Matrix<T, 7, 1> e;
    e.template head<3>() = t;
    const T wxyz[4] = {q.w(), q.x(), q.y(), q.z()};
    T angle_axis[3];
    ceres::QuaternionToAngleAxis(wxyz, angle_axis);
    e(3) = angle_axis[0];
    e(4) = angle_axis[1];
    e(5) = angle_axis[2];
    e(6) = log_s;
    return e;
  }
};

}  // namespace edgeslam
