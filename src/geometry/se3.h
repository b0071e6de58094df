#pragma once
// Rigid transform x -> R x + t, with the Lie-algebra exp/log (tangent = [rho; phi]).
#include <Eigen/Core>
#include <Eigen/Geometry>

namespace edgeslam {

using Vector6d = Eigen::Matrix<double, 6, 1>;

class SE3d {
 public:
  SE3d() : rotation_(Eigen::Quaterniond::Identity()), translation_(Eigen::Vector3d::Zero()) {}
  SE3d(const Eigen::Quaterniond& rotation, const Eigen::Vector3d& translation)
      : rotation_(rotation.normalized()), translation_(translation) {}
  SE3d(const Eigen::Matrix3d& rotation, const Eigen::Vector3d& translation);

  static SE3d identity() { return {}; }
  // Accepts a 4x4 or 3x4 matrix; the rotation block is re-orthonormalised.
  static SE3d fromMatrix(const Eigen::Matrix4d& m);
  static SE3d fromMatrix3x4(const Eigen::Matrix<double, 3, 4>& m);
  static SE3d exp(const Vector6d& xi);

  Vector6d log() const;
  SE3d inverse() const;
  Eigen::Matrix4d matrix() const;
  Eigen::Matrix<double, 3, 4> matrix3x4() const;

  const Eigen::Quaterniond& rotation() const { return rotation_; }
  Eigen::Matrix3d rotationMatrix() const { return rotation_.toRotationMatrix(); }
  const Eigen::Vector3d& translation() const { return translation_; }
  void setRotation(const Eigen::Quaterniond& q) { rotation_ = q.normalized(); }
  void setTranslation(const Eigen::Vector3d& t) { translation_ = t; }

  SE3d operator*(const SE3d& other) const {
    return {rotation_ * other.rotation_, rotation_ * other.translation_ + translation_};
  }
  Eigen::Vector3d operator*(const Eigen::Vector3d& point) const {
    return rotation_ * point + translation_;
  }

 private:
  Eigen::Quaterniond rotation_;
  Eigen::Vector3d translation_;
};

// Rotation angle in radians of a * b^-1 (0 when equal).
double rotationDistance(const SE3d& a, const SE3d& b);

}  // namespace edgeslam
