#pragma once
// Turns one image (plus optional depth) into FrameFeatures: ORB extraction, undistortion,
// per-keypoint depth and virtual right coordinate, grid.
#include <memory>
#include <opencv2/core.hpp>

#include "features/frame_features.h"
#include "features/orb_extractor.h"
#include "geometry/camera.h"

namespace edgeslam {

struct DepthOptions {
  // Baseline times fx used for RGB-D residuals (a virtual stereo rig); 0 = fx * 0.08 m.
  float bf = 0.f;
  float min_depth_m = 0.1f;
  float max_depth_m = 10.f;
};

// `depth` is CV_32FC1 metres registered to `gray` (raw pixel coordinates), or empty.
std::shared_ptr<FrameFeatures> buildFrameFeatures(const cv::Mat& gray, const cv::Mat& depth,
                                                  const PinholeCamera& camera,
                                                  OrbExtractor& extractor,
                                                  const DepthOptions& depth_options = {});

// The same from already extracted keypoints (raw image coordinates) and descriptors.
std::shared_ptr<FrameFeatures> buildFrameFeatures(std::vector<cv::KeyPoint> raw_keypoints,
                                                  cv::Mat descriptors, const cv::Mat& depth,
                                                  const PinholeCamera& camera,
                                                  const ScaleLevels& scales,
                                                  const DepthOptions& depth_options = {});

}  // namespace edgeslam
