#pragma once
// The map: owns keyframes and points by id and is the single place where they change, so every
// change is recorded (MapChanges) for the slices that keep client and edge in step.
//
// Thread safety: callers hold updateMutex() around any sequence of calls that reads or changes the
// map (tracking holds it for a frame; mapping for each change it applies). Every such method is
// REQUIRES(update_mutex_), so the clang build (-Wthread-safety) rejects a call without it; a caller
// names it as REQUIRES(map.updateMutex()). An erased element stays allocated until every thread
// that keeps pointers beyond the mutex (a MapParticipant) has passed a quiescent point; then an
// erased point is freed and an erased keyframe drops its features, leaving its pose in the spanning
// tree.
#include <cstdint>
#include <deque>
#include <memory>
#include <span>
#include <unordered_map>
#include <utility>
#include <vector>

#include "map/keyframe.h"
#include "map/map_changes.h"
#include "map/map_point.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

class MapParticipant;

class Map {
 public:
  explicit Map(std::uint8_t id_origin = 0);
  Map(const Map&) = delete;
  Map& operator=(const Map&) = delete;

  Mutex& updateMutex() const RETURN_CAPABILITY(update_mutex_) { return update_mutex_; }

  // Creation. `id` = kInvalidId allocates a fresh one; a given id is used as is (replicas).
  KeyFrame* createKeyFrame(std::size_t frame_index, double timestamp,
                           std::shared_ptr<const FrameFeatures> features, const SE3d& T_cw,
                           KeyFrameId id = kInvalidId) REQUIRES(update_mutex_);
  MapPoint* createMapPoint(const Eigen::Vector3d& position, KeyFrame* reference,
                           MapPointId id = kInvalidId) REQUIRES(update_mutex_);

  // Observations link a point and a keypoint both ways.
  void addObservation(MapPoint* point, KeyFrame* keyframe, std::size_t index)
      REQUIRES(update_mutex_);
  // Unlinks; a point left with fewer than two observations is erased.
  void eraseObservation(MapPoint* point, KeyFrame* keyframe) REQUIRES(update_mutex_);
  // Unlinks without that cull, erasing the point only when no observation is left: a replica
  // mirroring the other side, which culls for itself.
  void detachObservation(MapPoint* point, KeyFrame* keyframe) REQUIRES(update_mutex_);
  void erasePoint(MapPoint* point) REQUIRES(update_mutex_);
  // Moves every observation of `old_point` to `replacement` (point fusion) and erases `old_point`.
  void replacePoint(MapPoint* old_point, MapPoint* replacement) REQUIRES(update_mutex_);
  void setPointPosition(MapPoint* point, const Eigen::Vector3d& position) REQUIRES(update_mutex_);
  // Sets the position and recomputes what follows from it (normal, distance range), keeping the
  // descriptor: a replica applying a move.
  void relocatePoint(MapPoint* point, const Eigen::Vector3d& position) REQUIRES(update_mutex_);
  // Sets what refreshPoint would compute, as received from the other side of the wire.
  void setPointAppearance(MapPoint* point, const Eigen::Vector3d& normal, const cv::Mat& descriptor,
                          float min_distance, float max_distance) REQUIRES(update_mutex_);
  // Recomputes normal, distance range and representative descriptor from the observations.
  void refreshPoint(MapPoint* point) REQUIRES(update_mutex_);

  // Bulk load (a stored session into a map that has no points yet), none of it recorded as a
  // change: room for `count` more points; each point as createMapPoint, addObservation on each
  // observer in turn and setPointAppearance would make it; then every keyframe's covisibility
  // links as updateConnections on each keyframe in id order would make them, counted in one pass.
  struct PointLoad {
    MapPointId id = kInvalidId;
    Eigen::Vector3d position;
    KeyFrame* reference = nullptr;
    std::span<const std::pair<KeyFrame*, std::size_t>> observers;  // keyframe, keypoint index
    Eigen::Vector3d normal;
    const std::uint8_t* descriptor = nullptr;  // 32 bytes
    float min_distance = 0.f;
    float max_distance = 0.f;
  };
  void reservePoints(std::size_t count) REQUIRES(update_mutex_) {
    points_.reserve(points_.size() + count);
  }
  MapPoint* loadPoint(const PointLoad& load) REQUIRES(update_mutex_);
  void linkAllConnections() REQUIRES(update_mutex_);

  void setKeyFramePose(KeyFrame* keyframe, const SE3d& T_cw) REQUIRES(update_mutex_);
  void updateConnections(KeyFrame* keyframe) REQUIRES(update_mutex_);
  // Removes a redundant keyframe: unlinks its observations and re-parents its spanning-tree
  // children.
  // `covered_by`: the keyframe that saw the same (a revisit culled): the erased keyframe hangs
  // from it first, so its children, its pose and whoever follows the tree land there, where the
  // camera is, not at its old parent (on a merged map, possibly far behind).
  void eraseKeyFrame(KeyFrame* keyframe, KeyFrame* covered_by = nullptr) REQUIRES(update_mutex_);
  void addLoopEdge(KeyFrame* a, KeyFrame* b) REQUIRES(update_mutex_);
  // Joins two spanning trees (two parts of the map merged): `keyframe` becomes the root of its
  // own tree (the links on its way to the old root turn round), then a child of `parent`, which
  // must be in another tree. The keyframes whose parent changed are recorded as updated.
  void hangTreeFrom(KeyFrame* keyframe, KeyFrame* parent) REQUIRES(update_mutex_);
  // `ancestor` is `keyframe` or on its way to the root of the spanning tree.
  bool hangsFrom(const KeyFrame* keyframe, const KeyFrame* ancestor) const REQUIRES(update_mutex_);
  // A replica bounding what it holds: the keyframe keeps its id, pose and spanning-tree links (so
  // poses relative to it still follow corrections) but drops its features, its observations and
  // its covisibility links; points left without any observation are erased. No-op when bad or
  // already evicted.
  void evictKeyFrame(KeyFrame* keyframe) REQUIRES(update_mutex_);
  // Gives an evicted keyframe its features back (no points yet: the caller links them).
  void restoreKeyFrame(KeyFrame* keyframe, std::shared_ptr<const FrameFeatures> features)
      REQUIRES(update_mutex_);
  // Empties the map (a failed start); ids keep counting up.
  void clear() REQUIRES(update_mutex_);
  void protectKeyFrame(KeyFrame* keyframe) REQUIRES(update_mutex_) {
    keyframe->protected_from_culling_ = true;
  }

  std::size_t keyFrameCount() const REQUIRES(update_mutex_) { return keyframes_.size(); }
  // Keyframes that are not evicted (with their features and points).
  std::size_t heldKeyFrameCount() const REQUIRES(update_mutex_) {
    return keyframes_.size() - evicted_keyframes_;
  }
  std::size_t pointCount() const REQUIRES(update_mutex_) { return points_.size(); }
  std::vector<KeyFrame*> keyFrames() const REQUIRES(update_mutex_);  // sorted by id
  std::vector<MapPoint*> mapPoints() const REQUIRES(update_mutex_);  // sorted by id
  // Positions of at most `max_count` points spread over the map (every k-th in storage order, no
  // sorting): a cheap look for display while tracking waits on the mutex.
  std::vector<Eigen::Vector3d> pointPositionSample(std::size_t max_count) const
      REQUIRES(update_mutex_);
  // nullptr when absent or erased.
  KeyFrame* keyFrame(KeyFrameId id) const REQUIRES(update_mutex_);
  MapPoint* mapPoint(MapPointId id) const REQUIRES(update_mutex_);
  KeyFrame* originKeyFrame() const REQUIRES(update_mutex_) { return origin_; }

  const MapChanges& changes() const REQUIRES(update_mutex_) { return changes_; }
  MapChanges takeChanges() REQUIRES(update_mutex_);
  // While off, changes are applied but not recorded (a replica applying what the other side sent).
  void setChangeRecording(bool on) REQUIRES(update_mutex_) { recording_ = on; }

  // Needs no lock: the allocator is atomic.
  IdAllocator& ids() { return ids_; }

  // Erased elements freed so far, and those still waiting for a participant's quiescent point.
  struct Reclamation {
    std::uint64_t points_freed = 0;
    std::uint64_t keyframes_released = 0;  // features dropped; the erased keyframe stays
    std::size_t points_waiting = 0;
    std::size_t keyframes_waiting = 0;
    std::size_t participants = 0;
  };
  Reclamation reclamation() const REQUIRES(update_mutex_);

 private:
  friend class MapParticipant;
  struct RetiredPoint {
    std::uint64_t erasure;
    std::unique_ptr<MapPoint> point;
  };
  struct RetiredKeyFrame {
    std::uint64_t erasure;
    KeyFrame* keyframe;  // owned by erased_keyframes_
  };

  mutable Mutex update_mutex_;
  IdAllocator ids_;
  std::unordered_map<KeyFrameId, std::unique_ptr<KeyFrame>> keyframes_ GUARDED_BY(update_mutex_);
  std::unordered_map<MapPointId, std::unique_ptr<MapPoint>> points_ GUARDED_BY(update_mutex_);
  // Erasures are numbered; participants say through which number they hold nothing erased.
  std::uint64_t erasures_ GUARDED_BY(update_mutex_) = 0;
  std::deque<RetiredPoint> retired_points_ GUARDED_BY(update_mutex_);
  std::deque<RetiredKeyFrame> keyframes_to_release_ GUARDED_BY(update_mutex_);
  std::vector<std::unique_ptr<KeyFrame>> erased_keyframes_ GUARDED_BY(update_mutex_);
  std::vector<MapParticipant*> participants_ GUARDED_BY(update_mutex_);
  Reclamation reclaimed_ GUARDED_BY(update_mutex_);
  KeyFrame* origin_ GUARDED_BY(update_mutex_) = nullptr;
  // Live (not erased) keyframes that are evicted.
  std::size_t evicted_keyframes_ GUARDED_BY(update_mutex_) = 0;
  MapChanges changes_ GUARDED_BY(update_mutex_);
  MapChanges ignored_changes_ GUARDED_BY(update_mutex_);
  bool recording_ GUARDED_BY(update_mutex_) = true;

  MapChanges& record() REQUIRES(update_mutex_);
  void retire(std::unique_ptr<MapPoint> point) REQUIRES(update_mutex_);
  void retire(std::unique_ptr<KeyFrame> keyframe) REQUIRES(update_mutex_);
  // Frees what every participant has passed. Called from a quiescent point only: a map nobody
  // participates in keeps its erased elements until it is destroyed.
  void reclaim() REQUIRES(update_mutex_);
  // Covisibility links, both ways.
  void unlinkConnections(KeyFrame* keyframe) REQUIRES(update_mutex_);
};

}  // namespace edgeslam
