#include "server/slice_builder.h"

#include <algorithm>

#include "map/map_replication.h"

namespace edgeslam {
namespace {

template <typename Id>
std::vector<Id> sorted(const std::unordered_set<Id>& ids) {
  std::vector<Id> out(ids.begin(), ids.end());
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace

MapSlice buildSlice(const Map& map, const MapChanges& changes) {
  MapSlice slice;
  std::vector<MapPointId> points = sorted(changes.points_created);
  const std::vector<MapPointId> updated = sorted(changes.points_updated);
  points.insert(points.end(), updated.begin(), updated.end());
  for (MapPointId id : points) {
    const MapPoint* p = map.mapPoint(id);
    if (p != nullptr && !p->isBad()) slice.points_upserted.push_back(mapPointRecord(*p));
  }
  for (MapPointId id : sorted(changes.points_moved)) {
    const MapPoint* p = map.mapPoint(id);
    if (p != nullptr && !p->isBad()) slice.point_positions.push_back({id, p->position()});
  }
  slice.points_erased = sorted(changes.points_erased);

  std::vector<KeyFrameId> keyframes = sorted(changes.keyframes_created);
  const std::vector<KeyFrameId> updated_keyframes = sorted(changes.keyframes_updated);
  keyframes.insert(keyframes.end(), updated_keyframes.begin(), updated_keyframes.end());
  for (KeyFrameId id : keyframes) {
    const KeyFrame* kf = map.keyFrame(id);
    if (kf != nullptr && !kf->isBad()) slice.keyframe_poses.push_back(keyFramePoseRecord(*kf));
  }
  slice.keyframes_erased = sorted(changes.keyframes_erased);
  return slice;
}

}  // namespace edgeslam
