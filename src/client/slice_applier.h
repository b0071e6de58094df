#pragma once
// Applies the edge's map slices to the client's map: erased points and keyframes go, created and
// corrected points are written with their observations among the client's keyframes, keyframe
// poses take the edge's optimised values. With a bounded client map, the keyframes the edge
// evicts keep only their poses (their observations go, and the points no held keyframe sees),
// and keyframes back in the window get their features and points again; records naming what the
// client does not hold are ignored. Keyframes the client made after the slice's keyframe, and the
// points they made, follow that keyframe's correction rigidly. A slice with full_resync lists every
// keyframe of the edge's map: the client takes each pose and point it carries, keeps what it made
// that the edge lacks, and is told which keyframes those are (to send them again). The map's record
// of its own changes (Map::changes) is dropped: a client's is never read. Takes the map's update
// mutex for the duration.
#include <cstddef>
#include <vector>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_records.h"
#include "map/sensor.h"

namespace edgeslam {

struct SliceApplyResult {
  std::size_t points_upserted = 0;
  std::size_t points_moved = 0;
  std::size_t points_erased = 0;
  std::size_t keyframes_moved = 0;
  std::size_t keyframes_erased = 0;
  std::vector<KeyFrameId> erased_keyframe_ids;  // the slice's erasures the client applied
  // Keyframes newer than the slice's that followed its keyframe's correction.
  std::size_t keyframes_carried = 0;
  double carry_scale = 1.0;     // the scale they followed with (monocular loops and merges)
  std::size_t frame_index = 0;  // of the processed keyframe, 0 when the client does not have it
  std::vector<KeyFrameId> keyframes_evicted;  // held before, evicted now
  std::vector<KeyFrameId> keyframes_entered;  // held now, not (or evicted) before
  std::size_t points_evicted = 0;             // erased because only evicted keyframes saw them
  // The client's map after the slice: keyframes held (not evicted) and points.
  std::size_t keyframes_held = 0;
  std::size_t points_held = 0;
  // A full resync: the keyframes the client has (held or evicted) that the edge's map lacks.
  std::vector<KeyFrameId> keyframes_edge_lacks;
};

// `sensor`: a monocular map's loop corrections and merges change its scale, and the keyframes
// carried with the anchor follow that too (measured on the anchor's points).
SliceApplyResult applySlice(Map& map, const MapSlice& slice, const PinholeCamera& camera,
                            Sensor sensor) EXCLUDES(map.updateMutex());

}  // namespace edgeslam
