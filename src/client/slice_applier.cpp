#include "client/slice_applier.h"

#include <vector>

#include "map/map_replication.h"

namespace edgeslam {

SliceApplyResult applySlice(Map& map, const MapSlice& slice, const PinholeCamera& camera) {
  SliceApplyResult result;
  std::lock_guard lock(map.updateMutex());
  map.setChangeRecording(false);
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
      if (kf->isBad()) ++result.keyframes_erased;
    }
  }
  for (const KeyFramePoseRecord& record : slice.keyframe_poses) {
    if (KeyFrame* kf = map.keyFrame(record.id)) {
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
  for (KeyFrame* kf : touched) {
    if (kf != nullptr && !kf->isBad() && !kf->isEvicted()) map.updateConnections(kf);
  }
  if (const KeyFrame* processed = map.keyFrame(slice.processed_keyframe)) {
    result.frame_index = processed->frameIndex();
  }
  result.keyframes_held = map.heldKeyFrameCount();
  result.points_held = map.pointCount();
  map.setChangeRecording(true);
  return result;
}

}  // namespace edgeslam
