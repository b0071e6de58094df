#pragma once
// Turns what changed in the global map into the slice a client applies: records of created and
// updated points, erased ids, corrected keyframe poses. The caller holds the map's update mutex.
#include "map/map.h"
#include "map/map_changes.h"
#include "map/map_records.h"

namespace edgeslam {

MapSlice buildSlice(const Map& map, const MapChanges& changes) REQUIRES(map.updateMutex());

}  // namespace edgeslam
