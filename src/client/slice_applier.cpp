#include "client/slice_applier.h"

#include "map/map_replication.h"

namespace edgeslam {

SliceApplyResult applySlice(Map& map, const MapSlice& slice, const PinholeCamera& camera) {
  SliceApplyResult result;
  std::lock_guard lock(map.updateMutex());
  map.setChangeRecording(false);
  KeyFrameSet touched;
  for (const KeyFrameRecord& record : slice.keyframes) {
    touched.insert(insertKeyFrameRecord(map, record, camera));
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
  for (const MapPointRecord& record : slice.points_upserted) {
    if (MapPoint* p = upsertPointRecord(map, record, slice.newest_keyframe)) {
      for (const auto& [kf_id, obs] : p->observations()) touched.insert(obs.keyframe);
      ++result.points_upserted;
    }
  }
  for (const PointPositionRecord& record : slice.point_positions) {
    if (MapPoint* p = map.mapPoint(record.id)) {
      map.relocatePoint(p, record.position);
      ++result.points_moved;
    }
  }
  for (KeyFrame* kf : touched) {
    if (kf != nullptr && !kf->isBad()) map.updateConnections(kf);
  }
  if (const KeyFrame* processed = map.keyFrame(slice.processed_keyframe)) {
    result.frame_index = processed->frameIndex();
  }
  map.setChangeRecording(true);
  return result;
}

}  // namespace edgeslam
