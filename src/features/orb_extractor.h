#pragma once
// ORB features: a scale pyramid, FAST corners with a per-cell adaptive threshold, quadtree
// selection for an even spread, intensity-centroid orientation and steered-BRIEF descriptors.
#include <opencv2/core.hpp>
#include <vector>

#include "features/fast_grid_detector.h"
#include "features/orientation.h"
#include "features/scale_levels.h"

namespace edgeslam {

struct OrbExtractorOptions {
  int num_features = 1000;
  double scale_factor = 1.2;
  int num_levels = 8;
  int fast_threshold_initial = 20;  // FAST threshold tried first in every cell
  int fast_threshold_min = 7;       // retried in cells where the first found nothing
  int cell_size = 30;               // pixels of the level image
  // Keypoints keep this many pixels (of their level) from the border: the orientation patch and
  // the descriptor pattern both reach 15 px, so at least 15.
  int edge_border = 16;

  // Throws std::invalid_argument naming the offending field.
  void validate() const;
};

struct OrbFeatures {
  std::vector<cv::KeyPoint> keypoints;  // see OrbExtractor::extract
  cv::Mat descriptors;                  // CV_8UC1, keypoints.size() x 32
};

// Not thread-safe: an instance keeps its pyramid buffers between calls (one extractor per
// thread/camera).
class OrbExtractor {
 public:
  explicit OrbExtractor(const OrbExtractorOptions& options = {});

  // Extracts about options().num_features features from a CV_8UC1 image (CV_8UC3 / CV_8UC4 are
  // taken as BGR / BGRA and converted). Keypoints are ordered by level; pt is in level-0 pixels,
  // octave = level, angle in degrees [0, 360) in image coordinates, response = FAST score,
  // size = 31 * scale(level). Row i of the descriptors belongs to keypoint i. Throws
  // std::invalid_argument for an empty image or an unsupported type.
  void extract(const cv::Mat& image, std::vector<cv::KeyPoint>& keypoints, cv::Mat& descriptors);
  OrbFeatures extract(const cv::Mat& image);

  // Cheap run-time changes (the self-adaptation changes the pyramid depth per keyframe policy).
  void setNumLevels(int num_levels);
  void setNumFeatures(int num_features);

  const OrbExtractorOptions& options() const { return options_; }
  int numLevels() const { return options_.num_levels; }
  const ScaleLevels& scaleLevels() const { return scale_levels_; }
  // Number of features wanted per level (sums to num_features); levels that find fewer pass the
  // rest on to the next finer level.
  const std::vector<int>& featuresPerLevel() const { return features_per_level_; }
  // Pyramid level images of the last extract() (level 0 is a copy of the grey input).
  const cv::Mat& levelImage(int level) const { return pyramid_.at(level); }

 private:
  void configure();
  void buildPyramid(const cv::Mat& grey);

  OrbExtractorOptions options_;
  ScaleLevels scale_levels_;
  std::vector<int> features_per_level_;
  IntensityCentroid orientation_;
  std::vector<cv::Mat> pyramid_;
  std::vector<cv::Mat> blurred_;  // per level, so buffers are reused across frames
  cv::Mat grey_;
  std::vector<std::vector<cv::KeyPoint>> level_keypoints_;
  std::vector<cv::KeyPoint> candidates_;
};

}  // namespace edgeslam
