#include "geometry/triangulation.h"

#include <fmt/format.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <vector>

namespace edgeslam {
namespace {

// Homogeneous scale below which the point is treated as at infinity (unit-norm solution).
constexpr double kMinHomogeneousScale = 1e-12;

std::optional<Eigen::Vector3d> dehomogenize(const Eigen::Vector4d& x) {
  if (!x.allFinite() || std::abs(x.w()) < kMinHomogeneousScale) return std::nullopt;
  Eigen::Vector3d p = x.head<3>() / x.w();
  if (!p.allFinite()) return std::nullopt;
  return p;
}

template <typename Matrix>
void addViewRows(Matrix& A, int row, const Matrix34d& P, const Eigen::Vector2d& x) {
  A.row(row) = x.x() * P.row(2) - P.row(0);
  A.row(row + 1) = x.y() * P.row(2) - P.row(1);
}

}  // namespace

std::optional<Eigen::Vector3d> triangulateDlt(const Matrix34d& projection1,
                                              const Eigen::Vector2d& normalized1,
                                              const Matrix34d& projection2,
                                              const Eigen::Vector2d& normalized2) {
  Eigen::Matrix4d A;
  addViewRows(A, 0, projection1, normalized1);
  addViewRows(A, 2, projection2, normalized2);
  // Unit rows balance the system; the 4 x 4 normal matrix's eigen-decomposition is then accurate
  // and several times faster than an SVD (this runs per match and motion hypothesis).
  for (int r = 0; r < 4; ++r) {
    const double norm = A.row(r).norm();
    if (norm > 0.0) A.row(r) /= norm;
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d> eig(A.transpose() * A);
  return dehomogenize(eig.eigenvectors().col(0));
}

std::optional<Eigen::Vector3d> triangulateDlt(const SE3d& cam1_from_world,
                                              const Eigen::Vector2d& normalized1,
                                              const SE3d& cam2_from_world,
                                              const Eigen::Vector2d& normalized2) {
  return triangulateDlt(cam1_from_world.matrix3x4(), normalized1, cam2_from_world.matrix3x4(),
                        normalized2);
}

std::optional<Eigen::Vector3d> triangulateDlt(std::span<const SE3d> cams_from_world,
                                              std::span<const Eigen::Vector2d> normalized) {
  if (cams_from_world.size() != normalized.size() || cams_from_world.size() < 2) {
    throw std::invalid_argument(fmt::format(
        "triangulateDlt: need as many observations as poses and at least two (got {} poses, {} "
        "observations)",
        cams_from_world.size(), normalized.size()));
  }
  const int views = static_cast<int>(cams_from_world.size());
  Eigen::MatrixXd A(2 * views, 4);
  for (int i = 0; i < views; ++i) {
    addViewRows(A, 2 * i, cams_from_world[i].matrix3x4(), normalized[i]);
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullV);
  return dehomogenize(svd.matrixV().col(3));
}

std::optional<Eigen::Vector3d> triangulatePixels(
    const PinholeCamera& camera1, const SE3d& cam1_from_world, const Eigen::Vector2d& pixel1,
    const PinholeCamera& camera2, const SE3d& cam2_from_world, const Eigen::Vector2d& pixel2) {
  return triangulateDlt(cam1_from_world, camera1.unproject(pixel1).head<2>(), cam2_from_world,
                        camera2.unproject(pixel2).head<2>());
}

double reprojectionErrorSquared(const Eigen::Matrix3d& K, const SE3d& cam_from_world,
                                const Eigen::Vector3d& point_world, const Eigen::Vector2d& pixel) {
  const Eigen::Vector3d pc = cam_from_world * point_world;
  if (!(pc.z() > 0.0)) return std::numeric_limits<double>::infinity();
  const Eigen::Vector3d uv = K * (pc / pc.z());
  return (uv.head<2>() - pixel).squaredNorm();
}

double reprojectionErrorSquared(const PinholeCamera& camera, const SE3d& cam_from_world,
                                const Eigen::Vector3d& point_world, const Eigen::Vector2d& pixel) {
  const auto uv = camera.project(cam_from_world * point_world);
  if (!uv) return std::numeric_limits<double>::infinity();
  return (*uv - pixel).squaredNorm();
}

double parallaxCosine(const Eigen::Vector3d& center1, const Eigen::Vector3d& center2,
                      const Eigen::Vector3d& point_world) {
  const Eigen::Vector3d ray1 = point_world - center1;
  const Eigen::Vector3d ray2 = point_world - center2;
  const double norms = ray1.norm() * ray2.norm();
  if (!(norms > 0.0)) return 1.0;
  return std::clamp(ray1.dot(ray2) / norms, -1.0, 1.0);
}

double parallaxCosine(const SE3d& cam1_from_world, const SE3d& cam2_from_world,
                      const Eigen::Vector3d& point_world) {
  return parallaxCosine(cameraCenter(cam1_from_world), cameraCenter(cam2_from_world), point_world);
}

double parallaxDegrees(double parallax_cosine) {
  return std::acos(std::clamp(parallax_cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

}  // namespace edgeslam
