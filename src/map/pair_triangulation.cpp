#include "map/pair_triangulation.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "geometry/chi_square.h"
#include "geometry/triangulation.h"

namespace edgeslam {

std::string_view toString(PairRejection rejection) {
  switch (rejection) {
    case PairRejection::kNone:
      return "none";
    case PairRejection::kTooLittleParallax:
      return "too little parallax";
    case PairRejection::kDegenerate:
      return "degenerate";
    case PairRejection::kBehindCamera:
      return "behind a camera";
    case PairRejection::kReprojection:
      return "reprojection error";
    case PairRejection::kScaleInconsistent:
      return "scale inconsistent";
  }
  return "?";
}

namespace {

PairTriangulation rejected(PairRejection why) {
  return {std::nullopt, why};
}

}  // namespace

PairTriangulation triangulateKeypointPair(const KeyFrame& kf1, std::size_t i1, const KeyFrame& kf2,
                                          std::size_t i2, const PinholeCamera& camera,
                                          double min_parallax_deg) {
  const FrameFeatures& f1 = kf1.features();
  const FrameFeatures& f2 = kf2.features();
  if (i1 >= f1.keypoints.size() || i2 >= f2.keypoints.size()) {
    throw std::out_of_range("triangulateKeypointPair: keypoint " + std::to_string(i1) + " / " +
                            std::to_string(i2) + " of keyframes with " +
                            std::to_string(f1.keypoints.size()) + " / " +
                            std::to_string(f2.keypoints.size()) + " keypoints");
  }
  const SE3d& T1 = kf1.pose();
  const SE3d& T2 = kf2.pose();
  const cv::KeyPoint& kp1 = f1.keypoints[i1];
  const cv::KeyPoint& kp2 = f2.keypoints[i2];
  const Eigen::Vector2d px1(kp1.pt.x, kp1.pt.y), px2(kp2.pt.x, kp2.pt.y);
  const Eigen::Vector3d ray1 = T1.rotation().conjugate() * camera.unproject(px1).normalized();
  const Eigen::Vector3d ray2 = T2.rotation().conjugate() * camera.unproject(px2).normalized();
  const double ray_cos = ray1.dot(ray2);
  const double max_ray_cos = std::cos(min_parallax_deg * std::numbers::pi / 180.0);
  const bool depth1 = f1.hasDepth(i1), depth2 = f2.hasDepth(i2);
  // Parallax a stereo/depth measurement would give, to decide between rays and depth.
  const double depth_cos1 =
      depth1 ? std::cos(2 * std::atan2(f1.bf / camera.fx() / 2, f1.depth[i1])) : 1.1;
  const double depth_cos2 =
      depth2 ? std::cos(2 * std::atan2(f2.bf / camera.fx() / 2, f2.depth[i2])) : 1.1;
  const double depth_cos = std::min(depth_cos1, depth_cos2);

  std::optional<Eigen::Vector3d> x;
  if (ray_cos > 0 && ray_cos < depth_cos && (depth1 || depth2 || ray_cos < max_ray_cos)) {
    x = triangulateDlt(T1, camera.unproject(px1).head<2>(), T2, camera.unproject(px2).head<2>());
  } else if (depth1 && depth_cos1 < depth_cos2) {
    x = kf1.poseInverse() * (camera.unproject(px1) * f1.depth[i1]);
  } else if (depth2 && depth_cos2 < depth_cos1) {
    x = kf2.poseInverse() * (camera.unproject(px2) * f2.depth[i2]);
  } else {
    return rejected(ray_cos <= 0 ? PairRejection::kDegenerate : PairRejection::kTooLittleParallax);
  }
  if (!x || !x->allFinite()) return rejected(PairRejection::kDegenerate);
  if (!isInFrontOfBoth(T1, T2, *x)) return rejected(PairRejection::kBehindCamera);
  // Reprojection in both keyframes, at each keypoint's level.
  const double error1 =
      reprojectionErrorSquared(camera, T1, *x, px1) * f1.scales.invSigma2(kp1.octave);
  const double error2 =
      reprojectionErrorSquared(camera, T2, *x, px2) * f2.scales.invSigma2(kp2.octave);
  if (error1 > chi2::k2Dof95 || error2 > chi2::k2Dof95) {
    return rejected(PairRejection::kReprojection);
  }
  // Scale consistency: the distance ratio must agree with the pyramid level ratio.
  const double dist1 = (*x - kf1.cameraCenter()).norm(), dist2 = (*x - kf2.cameraCenter()).norm();
  if (dist1 <= 0 || dist2 <= 0) return rejected(PairRejection::kDegenerate);
  const double ratio_factor = 1.5 * f1.scales.scaleFactor();
  const double ratio_dist = dist2 / dist1;
  const double ratio_octave = f1.scales.scale(kp1.octave) / f2.scales.scale(kp2.octave);
  if (ratio_dist * ratio_factor < ratio_octave || ratio_dist > ratio_octave * ratio_factor) {
    return rejected(PairRejection::kScaleInconsistent);
  }
  return {x, PairRejection::kNone};
}

std::vector<std::pair<std::size_t, MapPoint*>> createPointsFromPairs(
    Map& map, KeyFrame* kf1, KeyFrame* kf2,
    const std::vector<std::pair<std::size_t, std::size_t>>& pairs, const PinholeCamera& camera,
    double min_parallax_deg) {
  std::vector<std::pair<std::size_t, MapPoint*>> created;
  for (const auto& [i1, i2] : pairs) {
    if (kf1->point(i1) != nullptr || kf2->point(i2) != nullptr) continue;
    const std::optional<Eigen::Vector3d> x =
        triangulateMatchedPair(*kf1, i1, *kf2, i2, camera, min_parallax_deg);
    if (!x) continue;
    MapPoint* p = map.createMapPoint(*x, kf1);
    map.addObservation(p, kf1, i1);
    map.addObservation(p, kf2, i2);
    map.refreshPoint(p);
    created.emplace_back(i1, p);
  }
  return created;
}

}  // namespace edgeslam
