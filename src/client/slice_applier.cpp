#include "client/slice_applier.h"

#include <algorithm>
#include <optional>
#include <unordered_map>
#include <unordered_set>
#include <utility>
#include <vector>

#include "map/ids.h"
#include "map/map_replication.h"

namespace edgeslam {
namespace {

// The client goes on tracking and making keyframes (and, monocular, points) while the edge
// optimises: those made after the slice's keyframe were placed against the map as it was, so when
// the slice moves that keyframe they follow it rigidly, keeping their relation to the map they
// were tracked in (as a loop correction carries the keyframes beyond the loop).
// `scale`: how much farther the anchor's surroundings lie from it after the correction (1 but for
// a monocular loop or merge, which corrects scale too): carried keyframes keep their rotation
// relative to the anchor and their offset from it times `scale`; their points likewise.
std::size_t carryNewerKeyFrames(Map& map, KeyFrameId anchor, const SE3d& anchor_before,
                                const SE3d& anchor_after, double scale,
                                const std::unordered_set<MapPointId>& points_in_slice,
                                const std::unordered_set<KeyFrameId>& keyframes_in_slice)
    REQUIRES(map.updateMutex()) {
  const SE3d anchor_before_inverse = anchor_before.inverse();
  const SE3d anchor_after_inverse = anchor_after.inverse();
  const auto carryPose = [&](const SE3d& pose) {
    const SE3d relative = pose * anchor_before_inverse;  // anchor camera -> this camera
    return SE3d(relative.rotation(), scale * relative.translation()) * anchor_after;
  };
  const auto carryPoint = [&](const Eigen::Vector3d& position) {  // old world -> new world
    return anchor_after_inverse * (scale * (anchor_before * position));
  };
  std::unordered_set<MapPointId> carried_points;
  std::size_t carried = 0;
  for (KeyFrame* kf : map.keyFrames()) {
    if (idOrigin(kf->id()) != idOrigin(anchor) || kf->id() <= anchor || kf->isBad() ||
        keyframes_in_slice.contains(kf->id())) {
      continue;  // the edge's own pose for it, when the slice has one, is the one to keep
    }
    map.setKeyFramePose(kf, carryPose(kf->pose()));
    ++carried;
    for (MapPoint* p : kf->points()) {
      if (p == nullptr || p->isBad() || points_in_slice.contains(p->id())) continue;
      const KeyFrameId born = p->firstKeyFrameId();
      if (born == kInvalidId || idOrigin(born) != idOrigin(anchor) || born <= anchor) continue;
      if (!carried_points.insert(p->id()).second) continue;
      map.relocatePoint(p, carryPoint(p->position()));
    }
  }
  return carried;
}

// Distances from a keyframe's camera centre to the points it sees, by point.
std::unordered_map<MapPointId, double> pointDistances(const KeyFrame& kf) {
  std::unordered_map<MapPointId, double> distances;
  const Eigen::Vector3d centre = kf.cameraCenter();
  for (const MapPoint* p : kf.points()) {
    if (p != nullptr && !p->isBad()) distances.emplace(p->id(), (p->position() - centre).norm());
  }
  return distances;
}

// The scale a correction gave the anchor's surroundings: the median ratio of its points'
// distances after and before, over the points the slice moved (1 with fewer than a few).
double correctionScale(const KeyFrame& anchor,
                       const std::unordered_map<MapPointId, double>& distances_before,
                       const std::unordered_set<MapPointId>& points_in_slice) {
  constexpr std::size_t kMinPoints = 8;
  std::vector<double> ratios;
  const Eigen::Vector3d centre = anchor.cameraCenter();
  for (const MapPoint* p : anchor.points()) {
    if (p == nullptr || p->isBad() || !points_in_slice.contains(p->id())) continue;
    const auto before = distances_before.find(p->id());
    if (before == distances_before.end() || !(before->second > 0.0)) continue;
    ratios.push_back((p->position() - centre).norm() / before->second);
  }
  if (ratios.size() < kMinPoints) return 1.0;
  const auto middle = ratios.begin() + static_cast<std::ptrdiff_t>(ratios.size() / 2);
  std::nth_element(ratios.begin(), middle, ratios.end());
  return *middle;
}

}  // namespace

SliceApplyResult applySlice(Map& map, const MapSlice& slice, const PinholeCamera& camera,
                            Sensor sensor) {
  SliceApplyResult result;
  MutexLock lock(map.updateMutex());
  // What the client's map recorded of its own changes since the last slice is read by nobody (its
  // uploads are built from its keyframes, not from the record): dropped here. Kept, the record held
  // every point the client made whose erasure came with a slice, unrecorded (~7000 ids and
  // ~0.25 MB of heap a pass of redkitchen 0-299, RGB-D, for good).
  map.takeChanges();
  map.setChangeRecording(false);
  // Before the slice's erasures: a keyframe the edge culled as soon as it had mapped it (a
  // revisit) still tells how far mapping has come.
  if (const KeyFrame* processed = map.keyFrame(slice.processed_keyframe)) {
    result.frame_index = processed->frameIndex();
  }
  KeyFrameSet touched;
  // Evictions first: the keyframes and points coming back below must not be dropped again.
  for (KeyFrameId id : slice.keyframes_evicted) {
    KeyFrame* kf = map.keyFrame(id);
    if (kf == nullptr || kf->isEvicted()) continue;
    const std::size_t points_before = map.pointCount();
    map.evictKeyFrame(kf);
    result.points_evicted += points_before - map.pointCount();
    result.keyframes_evicted.push_back(id);
  }
  for (const KeyFrameRecord& record : slice.keyframes) {
    const KeyFrame* before = map.keyFrame(record.id);
    const bool entering = before == nullptr || before->isEvicted();
    touched.insert(insertKeyFrameRecord(map, record, camera));
    if (entering) result.keyframes_entered.push_back(record.id);
  }
  for (MapPointId id : slice.points_erased) {
    if (MapPoint* p = map.mapPoint(id)) {
      for (const auto& [kf_id, obs] : p->observations()) touched.insert(obs.keyframe);
      map.erasePoint(p);
      ++result.points_erased;
    }
  }
  for (KeyFrameId id : slice.keyframes_erased) {
    if (KeyFrame* kf = map.keyFrame(id)) {
      map.eraseKeyFrame(kf);
      if (kf->isBad()) {
        ++result.keyframes_erased;
        result.erased_keyframe_ids.push_back(id);
      }
    }
  }
  // The keyframes newer than the anchor follow its move: the keyframe the slice mapped or, for a
  // loop correction (or a merge of two parts of the map), the newest the edge had of this client.
  const KeyFrameId anchor = slice.processed_keyframe != kInvalidId ? slice.processed_keyframe
                            : slice.loops_closed > 0               ? slice.newest_keyframe
                                                                   : kInvalidId;
  std::optional<std::pair<SE3d, SE3d>> anchor_move;  // the anchor keyframe's before, after
  // A monocular loop or merge corrects scale as well: measured on the anchor's points.
  const bool scale_may_change = sensor == Sensor::kMonocular && slice.loops_closed > 0;
  std::unordered_map<MapPointId, double> anchor_distances_before;
  if (const KeyFrame* kf = map.keyFrame(anchor); kf != nullptr && scale_may_change) {
    anchor_distances_before = pointDistances(*kf);
  }
  for (const KeyFramePoseRecord& record : slice.keyframe_poses) {
    if (KeyFrame* kf = map.keyFrame(record.id)) {
      if (record.id == anchor) anchor_move.emplace(kf->pose(), record.T_cw);
      map.setKeyFramePose(kf, record.T_cw);
      ++result.keyframes_moved;
    }
  }
  std::vector<KeyFrame*> observers_before;
  const auto observersOf = [](const MapPoint& p, std::vector<KeyFrame*>& out) {
    out.clear();
    for (const auto& [kf_id, obs] : p.observations()) out.push_back(obs.keyframe);
  };
  std::vector<KeyFrame*> observers_after;
  for (const MapPointRecord& record : slice.points_upserted) {
    // Covisibility changes only where a point's observers do: most upserts of a known point only
    // refresh its position and appearance, and re-linking every keyframe they touch was most of
    // a slice's cost on the client.
    const MapPoint* before = map.mapPoint(record.id);
    observers_before.clear();
    if (before != nullptr) observersOf(*before, observers_before);
    MapPoint* p = upsertPointRecord(map, record, slice.newest_keyframe);
    observers_after.clear();
    if (p != nullptr) {
      observersOf(*p, observers_after);
      ++result.points_upserted;
    }
    if (observers_after != observers_before) {
      touched.insert(observers_before.begin(), observers_before.end());
      touched.insert(observers_after.begin(), observers_after.end());
    }
  }
  for (const PointPositionRecord& record : slice.point_positions) {
    if (MapPoint* p = map.mapPoint(record.id)) {
      map.relocatePoint(p, record.position);
      ++result.points_moved;
    }
  }
  if (anchor_move && anchor != kInvalidId) {
    std::unordered_set<MapPointId> points_in_slice;
    for (const MapPointRecord& record : slice.points_upserted) points_in_slice.insert(record.id);
    for (const PointPositionRecord& record : slice.point_positions) {
      points_in_slice.insert(record.id);
    }
    std::unordered_set<KeyFrameId> keyframes_in_slice;
    for (const KeyFramePoseRecord& record : slice.keyframe_poses) {
      keyframes_in_slice.insert(record.id);
    }
    for (const KeyFrameRecord& record : slice.keyframes) keyframes_in_slice.insert(record.id);
    const KeyFrame* anchor_kf = map.keyFrame(anchor);
    result.carry_scale = scale_may_change && anchor_kf != nullptr
                             ? correctionScale(*anchor_kf, anchor_distances_before, points_in_slice)
                             : 1.0;
    result.keyframes_carried =
        carryNewerKeyFrames(map, anchor, anchor_move->first, anchor_move->second,
                            result.carry_scale, points_in_slice, keyframes_in_slice);
  }
  for (KeyFrame* kf : touched) {
    if (kf != nullptr && !kf->isBad() && !kf->isEvicted()) map.updateConnections(kf);
  }
  if (slice.full_resync) {
    std::unordered_set<KeyFrameId> on_edge;
    for (const KeyFramePoseRecord& record : slice.keyframe_poses) on_edge.insert(record.id);
    for (const KeyFrame* kf : map.keyFrames()) {
      if (!kf->isBad() && !on_edge.contains(kf->id())) {
        result.keyframes_edge_lacks.push_back(kf->id());
      }
    }
  }
  if (const KeyFrame* processed = map.keyFrame(slice.processed_keyframe)) {
    result.frame_index = std::max(result.frame_index, processed->frameIndex());
  }
  result.keyframes_held = map.heldKeyFrameCount();
  result.points_held = map.pointCount();
  map.setChangeRecording(true);
  return result;
}

}  // namespace edgeslam
