#include "geometry/relative_pose_refinement.h"

#include <fmt/format.h>

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "geometry/so3.h"

namespace edgeslam {
namespace {

using Vector5d = Eigen::Matrix<double, 5, 1>;
using Matrix5d = Eigen::Matrix<double, 5, 5>;

struct RelativePose {
  Eigen::Matrix3d R;
  Eigen::Vector3d t;  // unit norm

  Eigen::Matrix3d essential() const { return skew(t) * R; }

  // Rotation perturbed on the left, translation moved in the tangent plane of the unit sphere.
  RelativePose plus(const Vector5d& delta) const {
    Eigen::Vector3d b1 = t.unitOrthogonal();
    Eigen::Vector3d b2 = t.cross(b1);
    return {so3Exp(delta.head<3>()).toRotationMatrix() * R,
            (t + delta(3) * b1 + delta(4) * b2).normalized()};
  }
};

void residuals(const RelativePose& pose, std::span<const Eigen::Vector2d> x1,
               std::span<const Eigen::Vector2d> x2, Eigen::VectorXd& r) {
  const Eigen::Matrix3d E = pose.essential();
  for (size_t i = 0; i < x1.size(); ++i) {
    r(static_cast<Eigen::Index>(i)) = sampsonDistance(E, x1[i], x2[i]);
  }
}

}  // namespace

double sampsonDistance(const Eigen::Matrix3d& E21, const Eigen::Vector2d& normalized1,
                       const Eigen::Vector2d& normalized2) {
  const Eigen::Vector3d x1 = normalized1.homogeneous();
  const Eigen::Vector3d x2 = normalized2.homogeneous();
  const Eigen::Vector3d Ex1 = E21 * x1;
  const Eigen::Vector3d Etx2 = E21.transpose() * x2;
  const double denom = Ex1.head<2>().squaredNorm() + Etx2.head<2>().squaredNorm();
  if (!(denom > 0.0)) return 0.0;
  return x2.dot(Ex1) / std::sqrt(denom);  // signed, so that it can serve as a residual
}

SE3d refineRelativePose(const SE3d& cam2_from_cam1, std::span<const Eigen::Vector2d> normalized1,
                        std::span<const Eigen::Vector2d> normalized2, double cauchy_scale,
                        int max_iterations) {
  if (normalized1.size() != normalized2.size()) {
    throw std::invalid_argument(fmt::format("refineRelativePose: {} vs {} correspondences",
                                            normalized1.size(), normalized2.size()));
  }
  const double t_norm = cam2_from_cam1.translation().norm();
  if (normalized1.size() < 6 || !(t_norm > 0.0)) return cam2_from_cam1;

  const auto n = static_cast<Eigen::Index>(normalized1.size());
  RelativePose pose{cam2_from_cam1.rotationMatrix(), cam2_from_cam1.translation() / t_norm};
  Eigen::VectorXd r(n), r_plus(n), r_minus(n);
  Eigen::Matrix<double, Eigen::Dynamic, 5> J(n, 5);
  // Cauchy loss rho(r) = c^2 log(1 + r^2 / c^2), minimised by iteratively reweighted least
  // squares; plain least squares when no scale is given.
  const double c2 = cauchy_scale * cauchy_scale;
  auto robust_cost = [&](const Eigen::VectorXd& res) {
    if (!(c2 > 0.0)) return res.squaredNorm();
    return c2 * (res.array().square() / c2).log1p().sum();
  };
  Eigen::VectorXd weights = Eigen::VectorXd::Ones(n);
  residuals(pose, normalized1, normalized2, r);
  double cost = robust_cost(r);
  double lambda = 1e-4;
  constexpr double kStep = 1e-7;

  for (int it = 0; it < max_iterations; ++it) {
    // Central differences: five parameters and a cheap residual make this simpler than the
    // analytic Jacobian at negligible cost.
    for (int k = 0; k < 5; ++k) {
      Vector5d d = Vector5d::Zero();
      d(k) = kStep;
      residuals(pose.plus(d), normalized1, normalized2, r_plus);
      residuals(pose.plus(-d), normalized1, normalized2, r_minus);
      J.col(k) = (r_plus - r_minus) / (2.0 * kStep);
    }
    if (c2 > 0.0) weights = (1.0 + r.array().square() / c2).inverse().matrix();
    const Matrix5d JtJ = J.transpose() * weights.asDiagonal() * J;
    const Vector5d g = J.transpose() * weights.asDiagonal() * r;
    bool improved = false;
    for (int attempt = 0; attempt < 10 && !improved; ++attempt) {
      Matrix5d A = JtJ;
      A.diagonal() += lambda * JtJ.diagonal().cwiseMax(1e-12);
      const Vector5d delta = A.ldlt().solve(-g);
      if (!delta.allFinite()) break;
      const RelativePose candidate = pose.plus(delta);
      residuals(candidate, normalized1, normalized2, r_plus);
      const double candidate_cost = robust_cost(r_plus);
      if (candidate_cost < cost) {
        const double gain = cost - candidate_cost;
        pose = candidate;
        r = r_plus;
        cost = candidate_cost;
        lambda = std::max(lambda * 0.1, 1e-12);
        improved = true;
        if (gain < 1e-12 * cost || delta.norm() < 1e-12) return SE3d(pose.R, pose.t);
      } else {
        lambda *= 10.0;
      }
    }
    if (!improved) break;
  }
  return SE3d(pose.R, pose.t);
}

}  // namespace edgeslam
