#pragma once
// Map points that turn out to lie on movable objects: once a keyframe's segmentation is known,
// the points it observes inside the movable mask are removed from the map (they were made before
// the mask existed, or slipped past the transferred mask).
#include <cstddef>
#include <opencv2/core.hpp>

#include "map/map.h"

namespace edgeslam {

// Erases the points `keyframe` observes at keypoints inside `labels` (non-zero, full image size)
// shrunk by `erode_px`, so that background points along an object's outline survive. The caller
// holds the map's update mutex. Returns the number of points erased.
std::size_t eraseMovablePoints(Map& map, KeyFrame& keyframe, const cv::Mat1b& labels,
                               int erode_px = 2) REQUIRES(map.updateMutex());

}  // namespace edgeslam
