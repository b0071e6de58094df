#pragma once
// MediaPipe selfie segmentation (person probability per pixel) on OpenCV DNN, run on a padded crop
// around one person box.
#include <filesystem>
#include <opencv2/core.hpp>
#include <opencv2/dnn.hpp>

namespace edgeslam {

class PersonMaskModel {
 public:
  // Throws std::runtime_error naming the file when it is missing or not the selfie network.
  explicit PersonMaskModel(const std::filesystem::path& model_file);

  // Person probability (CV_32F, 0-1) over `crop` (clipped to the image) of the BGR image, at the
  // clipped crop's size. The crop is
  // letterboxed to the square network input so that the person keeps their proportions.
  cv::Mat1f probability(const cv::Mat& bgr, const cv::Rect& crop);

  static constexpr int kInputSize = 256;

 private:
  cv::dnn::Net net_;
};

}  // namespace edgeslam
