#pragma once
// What one image contributes to tracking and mapping: undistorted keypoints, descriptors, optional
// depth / virtual right coordinates, the pyramid's scale tables and a grid for area search.
#include <cstddef>
#include <opencv2/core.hpp>
#include <vector>

#include "features/feature_grid.h"
#include "features/scale_levels.h"

namespace edgeslam {

struct FrameFeatures {
  std::vector<cv::KeyPoint> keypoints;  // undistorted pixel coordinates; octave = pyramid level
  cv::Mat descriptors;                  // N x 32 CV_8U
  std::vector<float> depth;             // metres per keypoint, <= 0 where unknown (RGB-D/stereo)
  std::vector<float> right_u;           // virtual right-image x = u - bf / depth, < 0 where unknown
  ScaleLevels scales;
  FeatureGrid grid;
  float bf = 0.f;  // baseline times fx, for stereo/RGB-D residuals

  std::size_t size() const { return keypoints.size(); }
  bool hasDepth(std::size_t i) const { return !depth.empty() && depth[i] > 0.f; }
  cv::Mat descriptor(std::size_t i) const { return descriptors.row(static_cast<int>(i)); }
};

}  // namespace edgeslam
