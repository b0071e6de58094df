#pragma once
// Sees every change of a map as it is made, from the same change log the slices are built from
// (the map store's writer). Called under the map's update mutex: an observer only takes note and
// does its work elsewhere.
#include <vector>

#include "map/map_changes.h"
#include "map/map_records.h"

namespace edgeslam {

class MapChangeObserver {
 public:
  virtual ~MapChangeObserver() = default;
  virtual void onMapCleared() = 0;
  virtual void onMapChanged(const MapChanges& changes) = 0;
  virtual void onMasks(const std::vector<MaskRecord>& masks) = 0;
};

}  // namespace edgeslam
