#pragma once
// The record of what changed in a map since it was last cleared: the raw material of a map slice.
#include <unordered_set>

#include "map/ids.h"

namespace edgeslam {

struct MapChanges {
  std::unordered_set<MapPointId> points_created;
  std::unordered_set<MapPointId> points_updated;  // observations or descriptor changed
  std::unordered_set<MapPointId> points_moved;    // only the position (and what follows from it)
  std::unordered_set<MapPointId> points_erased;
  std::unordered_set<KeyFrameId> keyframes_created;
  std::unordered_set<KeyFrameId> keyframes_updated;  // pose or connections changed
  std::unordered_set<KeyFrameId> keyframes_erased;

  bool empty() const {
    return points_created.empty() && points_updated.empty() && points_moved.empty() &&
           points_erased.empty() && keyframes_created.empty() && keyframes_updated.empty() &&
           keyframes_erased.empty();
  }
  void clear() { *this = MapChanges{}; }

  void pointCreated(MapPointId id) { points_created.insert(id); }
  void pointUpdated(MapPointId id) {
    if (!points_created.contains(id)) points_updated.insert(id);
    points_moved.erase(id);
  }
  void pointMoved(MapPointId id) {
    if (!points_created.contains(id) && !points_updated.contains(id)) points_moved.insert(id);
  }
  void pointErased(MapPointId id) {
    // A point born and dead within one slice never needs to reach the other side.
    if (points_created.erase(id) == 0) points_erased.insert(id);
    points_updated.erase(id);
    points_moved.erase(id);
  }
  void keyFrameCreated(KeyFrameId id) { keyframes_created.insert(id); }
  void keyFrameUpdated(KeyFrameId id) {
    if (!keyframes_created.contains(id)) keyframes_updated.insert(id);
  }
  void keyFrameErased(KeyFrameId id) {
    if (keyframes_created.erase(id) == 0) keyframes_erased.insert(id);
    keyframes_updated.erase(id);
  }
};

}  // namespace edgeslam
