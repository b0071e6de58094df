// Fusion of duplicated points: a point projected into a keyframe either adds an observation or
// merges with the point the keyframe already has at that keypoint.
#include <fmt/format.h>

#include <algorithm>
#include <stdexcept>

#include "features/descriptor_distance.h"
#include "map/map_matching.h"
#include "map/map_matching_internal.h"

namespace edgeslam {
namespace {

constexpr float kChi2Mono = 5.99f;    // 2 degrees of freedom, 95 %
constexpr float kChi2Depth = 7.815f;  // 3 degrees of freedom, 95 %
constexpr float kMinViewCos = 0.5f;

}  // namespace

int fuse(Map& map, KeyFrame* keyframe, const std::vector<MapPoint*>& points,
         const PinholeCamera& camera, float radius) {
  if (keyframe == nullptr) throw std::invalid_argument("fuse: null keyframe");
  if (keyframe->isBad() || keyframe->size() == 0 || points.empty()) return 0;
  const FrameFeatures& features = keyframe->features();
  if (features.descriptors.rows != static_cast<int>(features.size())) {
    throw std::invalid_argument(fmt::format("fuse: keyframe {} has {} keypoints but {} descriptors",
                                            keyframe->id(), features.size(),
                                            features.descriptors.rows));
  }
  const int levels = features.scales.numLevels();
  const float scale_factor = static_cast<float>(features.scales.scaleFactor());
  const matching_detail::Projector projector(keyframe->pose(), camera);
  const Eigen::Vector3d center = keyframe->cameraCenter();
  const bool keyframe_has_depth = !features.depth.empty();

  std::vector<int> candidates;
  candidates.reserve(64);
  int fused = 0;
  for (MapPoint* point : points) {
    // A point may have been merged away earlier in this loop.
    if (!matching_detail::isUsable(point) || point->descriptor().empty()) continue;
    if (point->observations().contains(keyframe->id())) continue;
    Eigen::Vector3d camera_point;
    float u = 0.f, v = 0.f;
    if (!projector.project(point->position(), camera_point, u, v)) continue;
    const Eigen::Vector3d ray = point->position() - center;
    const float distance = static_cast<float>(ray.norm());
    if (distance < point->minDistance() || distance > point->maxDistance()) continue;
    if (static_cast<float>(ray.dot(point->normal())) < kMinViewCos * distance) continue;

    const int level = point->predictLevel(distance, scale_factor, levels);
    const float window = radius * static_cast<float>(features.scales.scale(level));
    features.grid.featuresInArea(u, v, window, std::max(0, level - 1), level, candidates);
    if (candidates.empty()) continue;

    const float right_u =
        keyframe_has_depth ? u - features.bf / static_cast<float>(camera_point.z()) : 0.f;
    const std::uint8_t* descriptor = point->descriptor().ptr<std::uint8_t>(0);
    int best_distance = kDescriptorBits + 1, best_index = -1;
    for (const int idx : candidates) {
      const auto j = static_cast<std::size_t>(idx);
      const cv::KeyPoint& kp = features.keypoints[j];
      const float eu = u - kp.pt.x, ev = v - kp.pt.y;
      const float inv_sigma2 = static_cast<float>(features.scales.invSigma2(kp.octave));
      if (features.hasDepth(j)) {
        const float er = right_u - features.right_u[j];
        if ((eu * eu + ev * ev + er * er) * inv_sigma2 > kChi2Depth) continue;
      } else if ((eu * eu + ev * ev) * inv_sigma2 > kChi2Mono) {
        continue;
      }
      const int d = descriptorDistance(descriptor, features.descriptors.ptr<std::uint8_t>(idx));
      if (d < best_distance) {
        best_distance = d;
        best_index = idx;
      }
    }
    if (best_index < 0 || best_distance > kMatchDistanceLow) continue;

    const auto j = static_cast<std::size_t>(best_index);
    MapPoint* existing = keyframe->point(j);
    if (matching_detail::isUsable(existing)) {
      // The better-established point survives.
      if (existing->observationCount() > point->observationCount()) {
        map.replacePoint(point, existing);
      } else {
        map.replacePoint(existing, point);
      }
    } else {
      map.addObservation(point, keyframe, j);
      map.refreshPoint(point);
    }
    ++fused;
  }
  return fused;
}

}  // namespace edgeslam
