#include "semantic/bgr_image.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace edgeslam {

cv::Mat toBgr8(const cv::Mat& image) {
  if (image.empty()) throw std::invalid_argument("segmenting an empty image");
  if (image.depth() != CV_8U) {
    throw std::invalid_argument("segmenting needs an 8-bit image, got OpenCV depth " +
                                std::to_string(image.depth()));
  }
  cv::Mat bgr;
  switch (image.channels()) {
    case 3:
      return image;
    case 1:
      cv::cvtColor(image, bgr, cv::COLOR_GRAY2BGR);
      return bgr;
    case 4:
      cv::cvtColor(image, bgr, cv::COLOR_BGRA2BGR);
      return bgr;
    default:
      throw std::invalid_argument("segmenting needs a 1-, 3- or 4-channel image, got " +
                                  std::to_string(image.channels()));
  }
}

}  // namespace edgeslam
