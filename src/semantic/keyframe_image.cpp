#include "semantic/keyframe_image.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>

namespace edgeslam {

void compressKeyFrameImage(KeyFrameUpload& upload, const KeyFrameImageOptions& options) {
  if (upload.raw_image.empty()) return;
  if (options.downscale < 1 || options.jpeg_quality < 1 || options.jpeg_quality > 100) {
    throw std::invalid_argument("keyframe image: downscale " + std::to_string(options.downscale) +
                                " (>= 1) or JPEG quality " + std::to_string(options.jpeg_quality) +
                                " (1..100) out of range");
  }
  const cv::Mat& image = upload.raw_image;
  if (image.type() != CV_8UC1 && image.type() != CV_8UC3) {
    throw std::invalid_argument("keyframe image must be 8-bit grey or BGR");
  }
  cv::Mat reduced = image;
  if (options.downscale > 1) {
    const cv::Size size((image.cols + options.downscale - 1) / options.downscale,
                        (image.rows + options.downscale - 1) / options.downscale);
    cv::resize(image, reduced, size, 0, 0, cv::INTER_AREA);
  }
  cv::imencode(".jpg", reduced, upload.image_bytes,
               {cv::IMWRITE_JPEG_QUALITY, options.jpeg_quality});
  upload.image_encoding = "jpeg";
  upload.raw_image.release();
}

}  // namespace edgeslam
