#pragma once
// A keyframe upload may leave out the descriptors of keypoints whose map point the edge already has
// (KeyFrameFeaturesRecord::descriptor_omitted): the keypoint matched that point within the matching
// threshold, so the point's representative descriptor stands in for it.
#include <cstddef>
#include <vector>

#include "map/map.h"
#include "map/map_records.h"

namespace edgeslam {

struct OmittedDescriptorFill {
  std::size_t filled = 0;
  // Keypoints whose point the map no longer has (erased or merged into another since the client
  // saw it): they lose the association and get a row of noise.
  std::vector<std::size_t> lost;
};

// Fills each omitted row of `keyframe` (a copy of the descriptors: the record's are not shared
// afterwards) with the descriptor of the point its keypoint names, and clears the omitted flags.
// A keypoint whose point is gone keeps no point (point_ids entry cleared) and a pseudo-random
// descriptor (seeded by keyframe and keypoint), ~128 bits from any ORB descriptor and from the
// other lost keypoints' rows, far beyond every matching threshold (<= 100). Caller holds the map's
// update mutex. Throws std::invalid_argument when the flags contradict the record (not one per
// keypoint, or an omitted keypoint without a point).
OmittedDescriptorFill fillOmittedDescriptors(const Map& map, KeyFrameRecord& keyframe)
    REQUIRES(map.updateMutex());

}  // namespace edgeslam
