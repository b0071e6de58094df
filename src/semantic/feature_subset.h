#pragma once
// The features of a frame without the ones on movable objects: what tracking and mapping get once
// the semantic mask has culled the dynamic features.
#include <memory>
#include <vector>

#include "features/frame_features.h"
#include "geometry/camera.h"

namespace edgeslam {

// A copy of `all` holding only the keypoints listed in `keep` (ascending indices into `all`), with
// their descriptors, depth and grid. Throws std::out_of_range for an index past the end.
std::shared_ptr<FrameFeatures> selectFeatures(const FrameFeatures& all,
                                              const std::vector<int>& keep,
                                              const PinholeCamera& camera);

}  // namespace edgeslam
