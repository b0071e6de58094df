#include "features/frame_features_builder.h"

#include "features/keypoint_undistortion.h"

namespace edgeslam {

std::shared_ptr<FrameFeatures> buildFrameFeatures(const cv::Mat& gray, const cv::Mat& depth,
                                                  const PinholeCamera& camera,
                                                  OrbExtractor& extractor,
                                                  const DepthOptions& depth_options) {
  std::vector<cv::KeyPoint> keypoints;
  cv::Mat descriptors;
  extractor.extract(gray, keypoints, descriptors);
  return buildFrameFeatures(std::move(keypoints), std::move(descriptors), depth, camera,
                            extractor.scaleLevels(), depth_options);
}

std::shared_ptr<FrameFeatures> buildFrameFeatures(std::vector<cv::KeyPoint> raw_keypoints,
                                                  cv::Mat descriptors, const cv::Mat& depth,
                                                  const PinholeCamera& camera,
                                                  const ScaleLevels& scales,
                                                  const DepthOptions& depth_options) {
  auto features = std::make_shared<FrameFeatures>();
  features->keypoints = undistortKeypoints(camera, raw_keypoints);
  features->descriptors = std::move(descriptors);
  features->scales = scales;
  const std::size_t n = features->keypoints.size();
  if (!depth.empty()) {
    features->bf =
        depth_options.bf > 0.f ? depth_options.bf : static_cast<float>(camera.fx()) * 0.08f;
    features->depth.assign(n, -1.f);
    features->right_u.assign(n, -1.f);
    for (std::size_t i = 0; i < n; ++i) {
      const int x = cvRound(raw_keypoints[i].pt.x);
      const int y = cvRound(raw_keypoints[i].pt.y);
      if (x < 0 || y < 0 || x >= depth.cols || y >= depth.rows) continue;
      const float d = depth.at<float>(y, x);
      if (d < depth_options.min_depth_m || d > depth_options.max_depth_m) continue;
      features->depth[i] = d;
      features->right_u[i] = features->keypoints[i].pt.x - features->bf / d;
    }
  }
  features->grid = FeatureGrid(camera.undistortedBounds(), features->keypoints);
  return features;
}

}  // namespace edgeslam
