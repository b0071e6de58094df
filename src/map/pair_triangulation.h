#pragma once
// One new map point from a keypoint pair matched between two keyframes (map_matching.h
// matchForTriangulation*): triangulated from the two rays (or, with depth, back-projected from the
// keypoint whose depth promises the wider parallax) and kept only when it is in front of both
// cameras, reprojects within the 95 % chi-square bound of each keypoint's pyramid level, and its
// distances to the two cameras agree with the two keypoints' scales. Pure: reads the keyframes'
// poses and features, changes nothing (callers hold the map's update mutex).
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <string_view>
#include <utility>
#include <vector>

#include "geometry/camera.h"
#include "map/keyframe.h"
#include "map/map.h"

namespace edgeslam {

// Two rays closer than this triangulate a point whose depth is mostly noise. Worse, the noise that
// widens a ray pair is what lets a far point through, so the points a low bound admits sit
// systematically too close, and a monocular map built from them shrinks as it goes: on KITTI 07
// (forward motion with two turns) 1.6 degrees instead of ORB-SLAM2's 1.15 gave an ATE median of
// 30.0 cm instead of 32.1 (16 and 9 runs, alternating); 7-Scenes monocular stayed at 4.0-4.2 cm.
inline constexpr double kDefaultMinTriangulationParallaxDeg = 1.6;

enum class PairRejection {
  kNone,
  // Rays closer than the minimum parallax (monocular) with no depth to fall back on.
  kTooLittleParallax,
  // Rays 90 degrees apart or more, no finite point, or a point on a camera centre.
  kDegenerate,
  kBehindCamera,
  kReprojection,  // over chi2(2 dof, 95 %) at the keypoint's level in either keyframe
  kScaleInconsistent,
};

std::string_view toString(PairRejection rejection);

struct PairTriangulation {
  std::optional<Eigen::Vector3d> position;  // world frame; set when rejection is kNone
  PairRejection rejection = PairRejection::kNone;
};

// Keypoint `i1` of `kf1` and keypoint `i2` of `kf2`, both undistorted pixels of `camera`. Throws
// std::out_of_range when an index is not a keypoint of its keyframe.
PairTriangulation triangulateKeypointPair(
    const KeyFrame& kf1, std::size_t i1, const KeyFrame& kf2, std::size_t i2,
    const PinholeCamera& camera, double min_parallax_deg = kDefaultMinTriangulationParallaxDeg);

// The position alone: nullopt when the pair is rejected.
inline std::optional<Eigen::Vector3d> triangulateMatchedPair(
    const KeyFrame& kf1, std::size_t i1, const KeyFrame& kf2, std::size_t i2,
    const PinholeCamera& camera, double min_parallax_deg = kDefaultMinTriangulationParallaxDeg) {
  return triangulateKeypointPair(kf1, i1, kf2, i2, camera, min_parallax_deg).position;
}

// Triangulates `pairs` (from matchForTriangulation*) and adds each accepted one to `map` as a new
// point (reference keyframe kf1) seen by both keyframes, refreshed. Pairs whose keypoint holds a
// point already, on either side, are skipped. Returns (keypoint index in kf1, point) per point.
std::vector<std::pair<std::size_t, MapPoint*>> createPointsFromPairs(
    Map& map, KeyFrame* kf1, KeyFrame* kf2,
    const std::vector<std::pair<std::size_t, std::size_t>>& pairs, const PinholeCamera& camera,
    double min_parallax_deg = kDefaultMinTriangulationParallaxDeg) REQUIRES(map.updateMutex());

}  // namespace edgeslam
