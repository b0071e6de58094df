#include "viz/frame_image.h"

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

namespace edgeslam::viz {

cv::Mat renderFrame(const FrameImage& frame, int max_width) {
  if (frame.image.empty()) return {};
  const double scale = std::min(1.0, static_cast<double>(max_width) / frame.image.cols);
  cv::Mat canvas;
  cv::resize(frame.image, canvas, cv::Size(), scale, scale, cv::INTER_AREA);
  if (canvas.channels() == 1) cv::cvtColor(canvas, canvas, cv::COLOR_GRAY2BGR);
  if (!frame.mask.empty()) {
    cv::Mat1b mask;
    cv::resize(frame.mask, mask, canvas.size(), 0, 0, cv::INTER_NEAREST);
    cv::Mat tinted = canvas.clone();
    tinted.setTo(cv::Scalar(200, 0, 255), mask);
    cv::addWeighted(canvas, 0.55, tinted, 0.45, 0.0, canvas);
  }
  const int radius = std::max(2, static_cast<int>(3 * scale + 0.5));
  for (const cv::Point2f& p : frame.fresh) {
    cv::circle(canvas, p * scale, std::max(1, radius / 2), kFreshColour, cv::FILLED, cv::LINE_AA);
  }
  for (const cv::Point2f& p : frame.on_map) {
    cv::circle(canvas, p * scale, radius, kOnMapColour, 1, cv::LINE_AA);
  }
  for (const cv::Point2f& p : frame.culled) {
    cv::drawMarker(canvas, p * scale, kCulledColour, cv::MARKER_TILTED_CROSS, 2 * radius + 1, 1,
                   cv::LINE_AA);
  }
  return canvas;
}

std::string renderFrameJpeg(const FrameImage& frame, int max_width, int quality) {
  const cv::Mat canvas = renderFrame(frame, max_width);
  if (canvas.empty()) return {};
  std::vector<uchar> bytes;
  cv::imencode(".jpg", canvas, bytes, {cv::IMWRITE_JPEG_QUALITY, quality});
  return {bytes.begin(), bytes.end()};
}

}  // namespace edgeslam::viz
