#pragma once
// A 3-D landmark: position, viewing direction, representative descriptor, scale range,
// observations. Mutated only through Map (under its update mutex) so that every change can be
// recorded.
#include <Eigen/Core>
#include <map>
#include <memory>
#include <opencv2/core.hpp>

#include "map/ids.h"

namespace edgeslam {

class KeyFrame;

class MapPoint {
 public:
  MapPoint(MapPointId id, const Eigen::Vector3d& position, KeyFrame* reference_keyframe);

  MapPointId id() const { return id_; }
  const Eigen::Vector3d& position() const { return position_; }
  const Eigen::Vector3d& normal() const { return normal_; }  // mean viewing direction, unit
  const cv::Mat& descriptor() const { return descriptor_; }  // 1x32 CV_8U
  KeyFrame* referenceKeyFrame() const { return reference_keyframe_; }
  bool isBad() const { return bad_; }
  MapPoint* replacedBy() const { return replaced_by_; }

  // Observations by keyframe, ordered by keyframe id for deterministic iteration.
  struct Observation {
    KeyFrame* keyframe;
    std::size_t index;  // keypoint index in that keyframe
  };
  const std::map<KeyFrameId, Observation>& observations() const { return observations_; }
  int observationCount() const { return observation_weight_; }  // stereo/RGB-D counts 2

  // Scale invariance: the distance range over which the point's descriptor is expected to match.
  float minDistance() const { return 0.8f * min_distance_; }
  float maxDistance() const { return 1.2f * max_distance_; }
  // The range as computed from the reference observation, without the margins (for replicas).
  float baseMinDistance() const { return min_distance_; }
  float baseMaxDistance() const { return max_distance_; }
  // Pyramid level where the point should be seen at `distance` (clamped to [0, levels-1]).
  int predictLevel(float distance, float scale_factor, int levels) const;

  void increaseVisible(int n = 1) { visible_ += n; }
  void increaseFound(int n = 1) { found_ += n; }
  float foundRatio() const { return visible_ > 0 ? static_cast<float>(found_) / visible_ : 0.f; }
  int visibleCount() const { return visible_; }
  int foundCount() const { return found_; }

  KeyFrameId firstKeyFrameId() const { return first_keyframe_id_; }

  // Tracking scratch state, owned by the tracker thread.
  std::size_t last_frame_seen = static_cast<std::size_t>(-1);
  std::size_t track_reference_frame = static_cast<std::size_t>(-1);
  float track_projected_x = 0.f, track_projected_y = 0.f, track_view_cos = 0.f;
  int track_level = 0;
  bool track_in_view = false;
  // Local-mapping scratch state.
  KeyFrameId fuse_candidate_for = kInvalidId;

 private:
  friend class Map;
  void updateNormalAndDepth();
  void computeDistinctiveDescriptor();

  MapPointId id_;
  Eigen::Vector3d position_;
  Eigen::Vector3d normal_ = Eigen::Vector3d::Zero();
  cv::Mat descriptor_;
  KeyFrame* reference_keyframe_;
  KeyFrameId first_keyframe_id_;
  std::map<KeyFrameId, Observation> observations_;
  int observation_weight_ = 0;
  float min_distance_ = 0.f;
  float max_distance_ = 0.f;
  int visible_ = 1;
  int found_ = 1;
  bool bad_ = false;
  MapPoint* replaced_by_ = nullptr;
};

}  // namespace edgeslam
