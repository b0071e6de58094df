#pragma once
// A synthetic bundle-adjustment window: keyframes along a gentle sideways/forward path looking at a
// cloud of points, each point observed by a few keyframes that see it.
#include <random>
#include <vector>

#include "optimize/local_bundle_adjustment.h"
#include "synthetic_scene.h"

namespace edgeslam::test {

struct BundleScene {
  BundleAdjustmentProblem truth;  // exact poses, points and observations
};

inline BundleScene makeBundleScene(int keyframes, int points, std::mt19937& rng,
                                   double pixel_noise = 0.0, int stereo_every = 0,
                                   int max_views_per_point = 5) {
  BundleScene scene;
  BundleAdjustmentProblem& p = scene.truth;
  p.camera = testCamera();
  std::normal_distribution<double> n(0.0, 1.0);
  for (int k = 0; k < keyframes; ++k) {
    const double s = 0.12 * k;
    const Eigen::Vector3d centre(s, 0.02 * std::sin(3.0 * s), 0.3 * s);
    const Eigen::Quaterniond R_wc(
        Eigen::AngleAxisd(0.05 * std::sin(2.0 * s), Eigen::Vector3d::UnitY()));
    const SE3d T_wc(R_wc, centre);
    p.keyframes.push_back({static_cast<std::uint64_t>(100 + k), T_wc.inverse(), false});
  }
  std::uniform_int_distribution<int> pick_kf(0, keyframes - 1);
  while (static_cast<int>(p.points.size()) < points) {
    const int anchor = pick_kf(rng);
    const Eigen::Vector3d X = randomVisiblePoint(p.keyframes[anchor].T_cw, rng, 3.0, 10.0);
    const std::size_t i = p.points.size();
    // The anchor and up to max_views_per_point - 1 following keyframes that see it; points seen
    // only once are dropped (their depth would be free).
    std::vector<BAObservation> seen;
    for (int d = 0; d < keyframes && static_cast<int>(seen.size()) < max_views_per_point; ++d) {
      const int k = (anchor + d) % keyframes;
      const Eigen::Vector3d pc = p.keyframes[k].T_cw * X;
      if (pc.z() <= 0.1) continue;
      const Eigen::Vector2d uv = p.camera.project(pc);
      if (uv.x() < 0 || uv.x() > 640 || uv.y() < 0 || uv.y() > 480) continue;
      BAObservation o;
      o.keyframe = static_cast<std::size_t>(k);
      o.point = i;
      o.pixel = uv + pixel_noise * Eigen::Vector2d(n(rng), n(rng));
      const bool stereo =
          stereo_every > 0 && (p.observations.size() + seen.size()) % stereo_every == 0;
      if (stereo) o.right_u = p.camera.rightU(pc) + pixel_noise * n(rng);
      o.inv_sigma2 = 1.0 / std::pow(1.2, 2 * (i % 3));
      seen.push_back(o);
    }
    if (seen.size() < 2) continue;
    p.points.push_back({static_cast<std::uint64_t>(1000 + i), X, false});
    p.observations.insert(p.observations.end(), seen.begin(), seen.end());
  }
  return scene;
}

}  // namespace edgeslam::test
