#pragma once
// Applies the edge's map slices to the client's map: erased points and keyframes go, created and
// corrected points are written with their observations among the client's keyframes, keyframe
// poses take the edge's optimised values. Takes the map's update mutex for the duration.
#include <cstddef>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_records.h"

namespace edgeslam {

struct SliceApplyResult {
  std::size_t points_upserted = 0;
  std::size_t points_moved = 0;
  std::size_t points_erased = 0;
  std::size_t keyframes_moved = 0;
  std::size_t keyframes_erased = 0;
  std::size_t frame_index = 0;  // of the processed keyframe, 0 when the client does not have it
};

SliceApplyResult applySlice(Map& map, const MapSlice& slice, const PinholeCamera& camera);

}  // namespace edgeslam
