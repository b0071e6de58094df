#pragma once
// Synthetic two-view scenes for the geometry solver tests: points seen by a reference and a
// current camera, with pixel noise and a fraction of gross outliers among the matches.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "geometry/se3.h"

namespace edgeslam::test {

inline Eigen::Matrix3d syntheticK() {
  Eigen::Matrix3d K;
  K << 520.0, 0.0, 320.0, 0.0, 520.0, 240.0, 0.0, 0.0, 1.0;
  return K;
}
inline constexpr double kImageWidth = 640.0;
inline constexpr double kImageHeight = 480.0;

inline double degToRad(double deg) {
  return deg * std::numbers::pi / 180.0;
}
inline double radToDeg(double rad) {
  return rad * 180.0 / std::numbers::pi;
}

inline SE3d makePose(const Eigen::Vector3d& axis, double angle_deg,
                     const Eigen::Vector3d& translation) {
  return SE3d(Eigen::Quaterniond(Eigen::AngleAxisd(degToRad(angle_deg), axis.normalized())),
              translation);
}

struct SceneOptions {
  int num_points = 300;
  bool planar = false;
  double min_depth = 2.0, max_depth = 6.0;  // in the reference camera
  // Plane n . X = d in the reference camera (planar scenes).
  Eigen::Vector3d plane_normal = Eigen::Vector3d(0.1, -0.2, -1.0).normalized();
  double plane_distance = -4.0;
  double noise_px = 0.7;
  double outlier_fraction = 0.25;
  unsigned seed = 42;
};

struct TwoViewScene {
  Eigen::Matrix3d K = syntheticK();
  SE3d cur_from_ref;
  std::vector<Eigen::Vector3d> points_ref;  // true points, reference frame
  std::vector<Eigen::Vector2d> ref_px, cur_px;
  std::vector<char> outlier;
};

inline bool inImage(const Eigen::Vector2d& px) {
  return px.x() >= 0.0 && px.x() < kImageWidth && px.y() >= 0.0 && px.y() < kImageHeight;
}

inline TwoViewScene makeTwoViewScene(const SE3d& cur_from_ref, const SceneOptions& o) {
  TwoViewScene s;
  s.cur_from_ref = cur_from_ref;
  std::mt19937 rng(o.seed);
  std::uniform_real_distribution<double> ux(0.0, kImageWidth), uy(0.0, kImageHeight);
  std::uniform_real_distribution<double> depth(o.min_depth, o.max_depth), unit(0.0, 1.0);
  std::normal_distribution<double> noise(0.0, o.noise_px);
  const Eigen::Matrix3d K_inv = s.K.inverse();
  while (static_cast<int>(s.points_ref.size()) < o.num_points) {
    const Eigen::Vector2d px(ux(rng), uy(rng));
    const Eigen::Vector3d ray = K_inv * px.homogeneous();
    Eigen::Vector3d X;
    if (o.planar) {
      const double denom = o.plane_normal.dot(ray);
      if (std::abs(denom) < 1e-6) continue;
      X = ray * (o.plane_distance / denom);
    } else {
      X = ray * depth(rng);
    }
    if (X.z() <= 0.1) continue;
    const Eigen::Vector3d Xc = cur_from_ref * X;
    if (Xc.z() <= 0.1) continue;
    const Eigen::Vector2d cur = (s.K * Xc).hnormalized();
    if (!inImage(cur)) continue;
    s.points_ref.push_back(X);
    s.ref_px.push_back(px + Eigen::Vector2d(noise(rng), noise(rng)));
    s.cur_px.push_back(cur + Eigen::Vector2d(noise(rng), noise(rng)));
    s.outlier.push_back(0);
  }
  const int num_outliers = static_cast<int>(o.outlier_fraction * o.num_points);
  for (int i = 0; i < num_outliers; ++i) {
    // Spread outliers over the whole set; each lands far from its true position.
    const int k = static_cast<int>(static_cast<long>(i) * o.num_points / num_outliers);
    Eigen::Vector2d wrong;
    do {
      wrong = {ux(rng), uy(rng)};
    } while ((wrong - s.cur_px[k]).norm() < 30.0);
    s.cur_px[k] = wrong;
    s.outlier[k] = 1;
  }
  return s;
}

// Angle in degrees between two directions.
inline double angleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  const double c = a.normalized().dot(b.normalized());
  return radToDeg(std::acos(std::clamp(c, -1.0, 1.0)));
}

}  // namespace edgeslam::test
