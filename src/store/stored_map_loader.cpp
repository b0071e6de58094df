#include "store/stored_map_loader.h"

#include <stdexcept>

#include "map/map_replication.h"
#include "store/store_error.h"

namespace edgeslam {

void loadStoredSession(const StoredSession& session, Map& map) {
  std::lock_guard lock(map.updateMutex());
  map.setChangeRecording(false);
  try {
    KeyFrameId newest = kInvalidId;
    for (const KeyFrameRecord& record : session.keyframes) {
      KeyFrameRecord without_points = record;
      without_points.point_ids.clear();  // linked by the points' observations below
      insertKeyFrameRecord(map, without_points, session.info.camera);
      map.ids().advancePast(record.id);
      newest = std::max(newest, record.id);
    }
    for (const MapPointRecord& record : session.points) {
      upsertPointRecord(map, record, newest);
      map.ids().advancePast(record.id);
    }
    for (KeyFrame* keyframe : map.keyFrames()) map.updateConnections(keyframe);
  } catch (const std::invalid_argument& e) {
    map.setChangeRecording(true);
    throw StoreError(std::string("stored session does not load: ") + e.what());
  }
  map.setChangeRecording(true);
}

}  // namespace edgeslam
