#pragma once
// A keyframe: a frame's features kept in the map, its pose, the points it observes and its place in
// the covisibility graph and spanning tree. Mutated only through Map (under its update mutex).
#include <atomic>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "features/frame_features.h"
#include "geometry/se3.h"
#include "map/ids.h"
#include "place/bow_vector.h"
#include "place/feature_vector.h"

namespace edgeslam {

class MapPoint;
class KeyFrame;

// Orders keyframes by id so that graph traversals are deterministic run to run.
struct KeyFrameIdLess {
  bool operator()(const KeyFrame* a, const KeyFrame* b) const;
};
using KeyFrameSet = std::set<KeyFrame*, KeyFrameIdLess>;

class Vocabulary;

// A keyframe's bag of words and direct index (features filed under their vocabulary node at
// `direct_index_depth`), computed once from the session's vocabulary.
struct KeyFramePlace {
  BowVector bow;
  FeatureVector features;
  int direct_index_depth = 0;
  const Vocabulary* vocabulary = nullptr;  // which one, to compare only; not owned
};

class KeyFrame {
 public:
  KeyFrame(KeyFrameId id, std::size_t frame_index, double timestamp,
           std::shared_ptr<const FrameFeatures> features, const SE3d& T_cw);

  KeyFrameId id() const { return id_; }
  std::size_t frameIndex() const { return frame_index_; }
  double timestamp() const { return timestamp_; }
  const FrameFeatures& features() const { return *features_; }
  const std::shared_ptr<const FrameFeatures>& sharedFeatures() const { return features_; }
  std::size_t size() const { return points_.size(); }

  const SE3d& pose() const { return T_cw_; }  // camera-from-world
  const SE3d& poseInverse() const { return T_wc_; }
  // The pose as corrected since, following the spanning tree when this keyframe was erased.
  SE3d latestPose() const;
  Eigen::Vector3d cameraCenter() const { return T_wc_.translation(); }

  MapPoint* point(std::size_t index) const { return points_[index]; }
  const std::vector<MapPoint*>& points() const { return points_; }
  // Good (not bad) points, and how many of them have at least `min_observations`.
  std::vector<MapPoint*> goodPoints() const;
  int trackedPointCount(int min_observations) const;
  // Median depth of the observed points in this camera (for scale and baselines).
  double medianSceneDepth() const;

  // Covisibility: keyframes sharing points, with the number of shared points as weight.
  const std::map<KeyFrame*, int, KeyFrameIdLess>& connections() const {
    return connection_weights_;
  }
  std::vector<KeyFrame*> bestCovisibles(std::size_t n) const;
  std::vector<KeyFrame*> covisiblesWithWeightAtLeast(int weight) const;
  int weight(KeyFrame* other) const;

  KeyFrame* parent() const { return parent_; }
  const KeyFrameSet& children() const { return children_; }
  const KeyFrameSet& loopEdges() const { return loop_edges_; }
  bool isBad() const { return bad_; }
  bool isProtected() const { return protected_from_culling_; }
  // A replica's keyframe outside the part of the map it holds: id, pose and spanning-tree place
  // only; no features, points or covisibility (Map::evictKeyFrame).
  bool isEvicted() const { return evicted_; }

  // Set once (by local mapping, when it has a vocabulary) and then read-only; safe from any
  // thread. nullptr until then. Describes the features the keyframe had when it was set.
  std::shared_ptr<const KeyFramePlace> place() const { return place_.load(); }
  void setPlace(std::shared_ptr<const KeyFramePlace> place) { place_.store(std::move(place)); }

  // Tracking / mapping scratch state.
  std::size_t track_reference_for_frame = static_cast<std::size_t>(-1);
  KeyFrameId fuse_target_for = kInvalidId;

 private:
  friend class Map;
  void setPose(const SE3d& T_cw);
  void updateConnections();  // recomputes covisibility from shared points; sets parent if none
  // Keeps only what projections need of the features (scales, bf): an evicted or erased keyframe.
  void dropFeatures();

  KeyFrameId id_;
  std::size_t frame_index_;
  double timestamp_;
  std::shared_ptr<const FrameFeatures> features_;
  std::atomic<std::shared_ptr<const KeyFramePlace>> place_;
  SE3d T_cw_;
  SE3d T_wc_;
  std::vector<MapPoint*> points_;
  std::map<KeyFrame*, int, KeyFrameIdLess> connection_weights_;
  std::vector<std::pair<int, KeyFrame*>> ordered_connections_;  // by weight, descending
  KeyFrame* parent_ = nullptr;
  KeyFrameSet children_;
  KeyFrameSet loop_edges_;
  bool first_connection_ = true;
  bool bad_ = false;
  bool evicted_ = false;
  bool protected_from_culling_ = false;
  SE3d T_cp_;  // camera-from-parent, frozen when the keyframe is erased
};

inline bool KeyFrameIdLess::operator()(const KeyFrame* a, const KeyFrame* b) const {
  return a->id() < b->id();
}

}  // namespace edgeslam
