#pragma once
// Similarity transform x -> s R x + t, with exp/log (tangent = [rho; phi; sigma], s = e^sigma).
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "geometry/se3.h"

namespace edgeslam {

using Vector7d = Eigen::Matrix<double, 7, 1>;

class Sim3d {
 public:
  Sim3d() = default;
  Sim3d(double scale, const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation);
  explicit Sim3d(const SE3d& rigid) : Sim3d(1.0, rigid.rotation(), rigid.translation()) {}

  static Sim3d identity() { return {}; }
  static Sim3d exp(const Vector7d& xi);
  Vector7d log() const;

  Sim3d inverse() const;
  Eigen::Matrix4d matrix() const;
  // The rigid part with the translation divided by the scale (the pose a Sim3 correction implies).
  SE3d toSE3() const { return {rotation_, translation_ / scale_}; }

  double scale() const { return scale_; }
  const Eigen::Quaterniond& rotation() const { return rotation_; }
  const Eigen::Vector3d& translation() const { return translation_; }

  Sim3d operator*(const Sim3d& o) const {
    return {scale_ * o.scale_, rotation_ * o.rotation_,
            scale_ * (rotation_ * o.translation_) + translation_};
  }
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const {
    return scale_ * (rotation_ * p) + translation_;
  }

 private:
  double scale_ = 1.0;
  Eigen::Quaterniond rotation_ = Eigen::Quaterniond::Identity();
  Eigen::Vector3d translation_ = Eigen::Vector3d::Zero();
};

}  // namespace edgeslam
