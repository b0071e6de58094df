// Matching by projection: frustum test, motion-model search (last frame -> current), local-map
// search and the relocalisation refinement against one keyframe.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "features/descriptor_distance.h"
#include "features/rotation_histogram.h"
#include "map/map_matching.h"
#include "map/map_matching_internal.h"

namespace edgeslam {

using matching_detail::BestTwoWithLevels;
using matching_detail::isUsable;
using matching_detail::Projector;

namespace {

// Descriptor to search with: the point's representative one, or the observing keypoint's when the
// point was never refreshed.
const std::uint8_t* searchDescriptor(const MapPoint& point, const FrameFeatures& observer,
                                     std::size_t index) {
  if (!point.descriptor().empty()) return point.descriptor().ptr<std::uint8_t>(0);
  return observer.descriptors.ptr<std::uint8_t>(static_cast<int>(index));
}

// Virtual right-image coordinate of a projection at depth z, for the RGB-D/stereo consistency
// check (only meaningful where the candidate keypoint has depth).
inline float rightCoordinate(float u, double z, float bf) {
  return u - static_cast<float>(bf / z);
}

int clampLevel(int level, int levels) {
  return std::clamp(level, 0, levels - 1);
}

}  // namespace

bool isInFrustum(MapPoint* point, const Frame& frame, float min_view_cos) {
  if (point == nullptr) throw std::invalid_argument("isInFrustum: null map point");
  point->track_in_view = false;
  if (point->isBad()) return false;
  matching_detail::requireFeatures(frame, "isInFrustum");
  const PinholeCamera& camera = matching_detail::requireCamera(frame, "isInFrustum");
  const SE3d& T_cw = matching_detail::requirePose(frame, "isInFrustum");

  Eigen::Vector3d camera_point;
  float u = 0.f, v = 0.f;
  if (!Projector(T_cw, camera).project(point->position(), camera_point, u, v)) return false;

  const Eigen::Vector3d ray = point->position() - T_cw.inverse().translation();
  const float distance = static_cast<float>(ray.norm());
  if (distance < point->minDistance() || distance > point->maxDistance()) return false;
  const float view_cos = static_cast<float>(ray.dot(point->normal())) / distance;
  if (!(view_cos >= min_view_cos)) return false;

  const ScaleLevels& scales = frame.features->scales;
  point->track_projected_x = u;
  point->track_projected_y = v;
  point->track_view_cos = view_cos;
  point->track_level =
      point->predictLevel(distance, static_cast<float>(scales.scaleFactor()), scales.numLevels());
  point->track_in_view = true;
  return true;
}

int matchByProjection(Frame& current, const Frame& last, float radius, bool monocular) {
  constexpr const char* kWho = "matchByProjection";
  matching_detail::requireFeatures(current, kWho);
  matching_detail::requireFeatures(last, kWho);
  const PinholeCamera& camera = matching_detail::requireCamera(current, kWho);
  const SE3d& T_cw = matching_detail::requirePose(current, kWho);
  const SE3d& T_lw = matching_detail::requirePose(last, kWho);
  if (current.size() == 0 || last.size() == 0) return 0;

  const FrameFeatures& cur = *current.features;
  const FrameFeatures& prev = *last.features;
  const int levels = cur.scales.numLevels();
  const Projector projector(T_cw, camera);

  // With depth, a clear forward (backward) motion means points look bigger (smaller) now, so only
  // coarser (finer) levels than last time are searched.
  const double baseline = cur.bf > 0.f ? cur.bf / camera.fx() : 0.0;
  const double forward_motion = (T_lw * current.cameraCenter()).z();
  const bool forward = !monocular && baseline > 0.0 && forward_motion > baseline;
  const bool backward = !monocular && baseline > 0.0 && -forward_motion > baseline;
  const bool current_has_depth = !cur.depth.empty();

  RotationHistogram histogram;
  std::vector<int> candidates;
  candidates.reserve(64);
  int matches = 0;
  for (std::size_t i = 0; i < last.size(); ++i) {
    MapPoint* point = last.points[i];
    if (!isUsable(point) || last.outliers[i]) continue;
    Eigen::Vector3d camera_point;
    float u = 0.f, v = 0.f;
    if (!projector.project(point->position(), camera_point, u, v)) continue;

    const int octave = prev.keypoints[i].octave;
    const float window =
        radius * static_cast<float>(prev.scales.scale(clampLevel(octave, prev.scales.numLevels())));
    int min_level = std::max(0, octave - 1), max_level = octave + 1;
    if (forward) {
      min_level = octave;
      max_level = -1;
    } else if (backward) {
      min_level = 0;
      max_level = octave;
    }
    min_level = std::min(min_level, levels - 1);
    cur.grid.featuresInArea(u, v, window, min_level, max_level, candidates);
    if (candidates.empty()) continue;

    const std::uint8_t* descriptor = searchDescriptor(*point, prev, i);
    const float right_u = current_has_depth ? rightCoordinate(u, camera_point.z(), cur.bf) : 0.f;
    int best_distance = kDescriptorBits + 1, best_index = -1;
    for (const int idx : candidates) {
      const auto j = static_cast<std::size_t>(idx);
      if (isUsable(current.points[j])) continue;
      if (current_has_depth && cur.depth[j] > 0.f && std::abs(right_u - cur.right_u[j]) > window) {
        continue;
      }
      const int distance = descriptorDistance(descriptor, cur.descriptors.ptr<std::uint8_t>(idx));
      if (distance < best_distance) {
        best_distance = distance;
        best_index = idx;
      }
    }
    if (best_index < 0 || best_distance > kMatchDistanceHigh) continue;
    const auto j = static_cast<std::size_t>(best_index);
    current.points[j] = point;
    current.outliers[j] = false;
    histogram.add(prev.keypoints[i].angle, cur.keypoints[j].angle, best_index);
    ++matches;
  }
  return matches - matching_detail::removeRotationOutliers(histogram, current);
}

int matchLocalPoints(Frame& frame, const std::vector<MapPoint*>& points, float radius_factor,
                     float ratio) {
  constexpr const char* kWho = "matchLocalPoints";
  matching_detail::requireFeatures(frame, kWho);
  if (frame.size() == 0 || points.empty()) return 0;
  const FrameFeatures& features = *frame.features;
  const int levels = features.scales.numLevels();
  // The stereo check needs the point's depth in this frame, hence the pose.
  const bool use_depth = !features.depth.empty() && frame.T_cw.has_value();
  const Eigen::Matrix3d R = use_depth ? frame.T_cw->rotationMatrix() : Eigen::Matrix3d::Identity();
  const Eigen::Vector3d t = use_depth ? frame.T_cw->translation() : Eigen::Vector3d::Zero();

  const std::vector<const MapPoint*> already = matching_detail::sortedUsablePoints(frame.points);
  std::vector<int> candidates;
  candidates.reserve(64);
  int matches = 0;
  for (MapPoint* point : points) {
    if (!isUsable(point) || !point->track_in_view || point->descriptor().empty()) continue;
    if (matching_detail::containsPoint(already, point)) continue;
    const int level = clampLevel(point->track_level, levels);
    // A point seen from an unusual angle looks less like its descriptor: search wider.
    const float angle_factor = point->track_view_cos > 0.998f ? 2.5f : 4.0f;
    const float window =
        radius_factor * angle_factor * static_cast<float>(features.scales.scale(level));
    const float u = point->track_projected_x, v = point->track_projected_y;
    features.grid.featuresInArea(u, v, window, std::max(0, level - 1), level, candidates);
    if (candidates.empty()) continue;

    float right_u = 0.f;
    if (use_depth) {
      const double z = (R * point->position() + t).z();
      right_u = z > 0.0 ? rightCoordinate(u, z, features.bf) : 0.f;
    }
    const std::uint8_t* descriptor = point->descriptor().ptr<std::uint8_t>(0);
    BestTwoWithLevels best;
    for (const int idx : candidates) {
      const auto j = static_cast<std::size_t>(idx);
      if (isUsable(frame.points[j])) continue;
      if (use_depth && features.depth[j] > 0.f &&
          std::abs(right_u - features.right_u[j]) > window) {
        continue;
      }
      best.consider(idx,
                    descriptorDistance(descriptor, features.descriptors.ptr<std::uint8_t>(idx)),
                    features.keypoints[j].octave);
    }
    if (best.index < 0 || best.distance > kMatchDistanceHigh) continue;
    if (best.level == best.second_level &&
        static_cast<float>(best.distance) > ratio * static_cast<float>(best.second_distance)) {
      continue;
    }
    const auto j = static_cast<std::size_t>(best.index);
    frame.points[j] = point;
    frame.outliers[j] = false;
    ++matches;
  }
  return matches;
}

int matchKeyFrameByProjection(Frame& frame, const KeyFrame& keyframe,
                              const std::vector<MapPoint*>& already_matched, float radius,
                              int max_distance) {
  constexpr const char* kWho = "matchKeyFrameByProjection";
  matching_detail::requireFeatures(frame, kWho);
  const PinholeCamera& camera = matching_detail::requireCamera(frame, kWho);
  const SE3d& T_cw = matching_detail::requirePose(frame, kWho);
  if (frame.size() == 0 || keyframe.size() == 0) return 0;

  const FrameFeatures& features = *frame.features;
  const FrameFeatures& kf_features = keyframe.features();
  const int levels = features.scales.numLevels();
  const float scale_factor = static_cast<float>(features.scales.scaleFactor());
  const Projector projector(T_cw, camera);
  const Eigen::Vector3d center = frame.cameraCenter();
  const std::vector<const MapPoint*> already = matching_detail::sortedUsablePoints(already_matched);

  RotationHistogram histogram;
  std::vector<int> candidates;
  candidates.reserve(64);
  int matches = 0;
  for (std::size_t i = 0; i < keyframe.size(); ++i) {
    MapPoint* point = keyframe.point(i);
    if (!isUsable(point) || matching_detail::containsPoint(already, point)) continue;
    Eigen::Vector3d camera_point;
    float u = 0.f, v = 0.f;
    if (!projector.project(point->position(), camera_point, u, v)) continue;
    const float distance = static_cast<float>((point->position() - center).norm());
    if (distance < point->minDistance() || distance > point->maxDistance()) continue;
    const int level = point->predictLevel(distance, scale_factor, levels);
    const float window = radius * static_cast<float>(features.scales.scale(level));
    features.grid.featuresInArea(u, v, window, std::max(0, level - 1), level + 1, candidates);
    if (candidates.empty()) continue;

    const std::uint8_t* descriptor = searchDescriptor(*point, kf_features, i);
    int best_distance = kDescriptorBits + 1, best_index = -1;
    for (const int idx : candidates) {
      if (isUsable(frame.points[static_cast<std::size_t>(idx)])) continue;
      const int d = descriptorDistance(descriptor, features.descriptors.ptr<std::uint8_t>(idx));
      if (d < best_distance) {
        best_distance = d;
        best_index = idx;
      }
    }
    if (best_index < 0 || best_distance > max_distance) continue;
    const auto j = static_cast<std::size_t>(best_index);
    frame.points[j] = point;
    frame.outliers[j] = false;
    histogram.add(kf_features.keypoints[i].angle, features.keypoints[j].angle, best_index);
    ++matches;
  }
  return matches - matching_detail::removeRotationOutliers(histogram, frame);
}

}  // namespace edgeslam
