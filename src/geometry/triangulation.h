#pragma once
// Linear (DLT) triangulation and the standard checks applied to a triangulated point.
// Poses are camera-from-world; "normalised" image points lie on the z = 1 plane (K^-1 * pixel).
#include <Eigen/Core>
#include <optional>
#include <span>

#include "geometry/camera.h"
#include "geometry/se3.h"

namespace edgeslam {

using Matrix34d = Eigen::Matrix<double, 3, 4>;

// Least-squares DLT (smallest right singular vector). nullopt when the solution lies at infinity
// (parallel rays) or is not finite. No cheirality check: see isInFront().
std::optional<Eigen::Vector3d> triangulateDlt(const Matrix34d& projection1,
                                              const Eigen::Vector2d& normalized1,
                                              const Matrix34d& projection2,
                                              const Eigen::Vector2d& normalized2);
std::optional<Eigen::Vector3d> triangulateDlt(const SE3d& cam1_from_world,
                                              const Eigen::Vector2d& normalized1,
                                              const SE3d& cam2_from_world,
                                              const Eigen::Vector2d& normalized2);
// N-view version; throws std::invalid_argument when sizes differ or fewer than two views.
std::optional<Eigen::Vector3d> triangulateDlt(std::span<const SE3d> cams_from_world,
                                              std::span<const Eigen::Vector2d> normalized);
// Same from undistorted pixels, each view with its own camera.
std::optional<Eigen::Vector3d> triangulatePixels(
    const PinholeCamera& camera1, const SE3d& cam1_from_world, const Eigen::Vector2d& pixel1,
    const PinholeCamera& camera2, const SE3d& cam2_from_world, const Eigen::Vector2d& pixel2);

// z of the point in the camera frame.
inline double depthInCamera(const SE3d& cam_from_world, const Eigen::Vector3d& point_world) {
  return (cam_from_world * point_world).z();
}
inline bool isInFront(const SE3d& cam_from_world, const Eigen::Vector3d& point_world,
                      double min_depth = 0.0) {
  return depthInCamera(cam_from_world, point_world) > min_depth;
}
inline bool isInFrontOfBoth(const SE3d& cam1_from_world, const SE3d& cam2_from_world,
                            const Eigen::Vector3d& point_world, double min_depth = 0.0) {
  return isInFront(cam1_from_world, point_world, min_depth) &&
         isInFront(cam2_from_world, point_world, min_depth);
}

// Squared pixel distance between the projection of a world point and an observed undistorted
// pixel; +infinity when the point is not in front of the camera.
double reprojectionErrorSquared(const Eigen::Matrix3d& K, const SE3d& cam_from_world,
                                const Eigen::Vector3d& point_world, const Eigen::Vector2d& pixel);
double reprojectionErrorSquared(const PinholeCamera& camera, const SE3d& cam_from_world,
                                const Eigen::Vector3d& point_world, const Eigen::Vector2d& pixel);

// Cosine of the angle between the rays from the two camera centres to the point (1 = parallel,
// no parallax). Returns 1 when the point coincides with a centre.
double parallaxCosine(const Eigen::Vector3d& center1, const Eigen::Vector3d& center2,
                      const Eigen::Vector3d& point_world);
double parallaxCosine(const SE3d& cam1_from_world, const SE3d& cam2_from_world,
                      const Eigen::Vector3d& point_world);
double parallaxDegrees(double parallax_cosine);

// World position of a camera centre.
inline Eigen::Vector3d cameraCenter(const SE3d& cam_from_world) {
  return -(cam_from_world.rotation().conjugate() * cam_from_world.translation());
}

}  // namespace edgeslam
