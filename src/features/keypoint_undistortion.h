#pragma once
// Removes lens distortion from keypoint positions; everything else about a keypoint is kept.
#include <opencv2/core.hpp>
#include <vector>

#include "geometry/camera.h"

namespace edgeslam {

// Same keypoints, same order, pt replaced by its undistorted position (a plain copy when the
// camera has no distortion).
std::vector<cv::KeyPoint> undistortKeypoints(const PinholeCamera& camera,
                                             const std::vector<cv::KeyPoint>& keypoints);

}  // namespace edgeslam
