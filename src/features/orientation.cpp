#include "features/orientation.h"

#include <fmt/format.h>

#include <cmath>
#include <cstdint>
#include <opencv2/core/fast_math.hpp>
#include <stdexcept>

namespace edgeslam {

IntensityCentroid::IntensityCentroid(int radius) : radius_(radius) {
  if (radius < 1) {
    throw std::invalid_argument(
        fmt::format("intensity centroid: radius must be at least 1 (got {})", radius));
  }
  // The patch is {(u, v) : u^2 + v^2 <= r^2}, symmetric under 90-degree rotations.
  half_width_.resize(radius + 1);
  for (int v = 0; v <= radius; ++v) {
    int u = 0;
    while ((u + 1) * (u + 1) + v * v <= radius * radius) ++u;
    half_width_[v] = u;
  }
}

float IntensityCentroid::angleAt(const cv::Mat& image, cv::Point2f point) const {
  const int cx = cvRound(point.x), cy = cvRound(point.y);
  const int step = static_cast<int>(image.step1());
  const std::uint8_t* center = image.ptr<std::uint8_t>(cy) + cx;
  int m10 = 0, m01 = 0;
  // Centre row, then rows +v and -v together.
  for (int u = -radius_; u <= radius_; ++u) m10 += u * center[u];
  for (int v = 1; v <= radius_; ++v) {
    const std::uint8_t* below = center + v * step;
    const std::uint8_t* above = center - v * step;
    const int w = half_width_[v];
    int row_difference = 0;
    for (int u = -w; u <= w; ++u) {
      const int b = below[u], a = above[u];
      row_difference += b - a;
      m10 += u * (b + a);
    }
    m01 += v * row_difference;
  }
  return cv::fastAtan2(static_cast<float>(m01), static_cast<float>(m10));
}

void IntensityCentroid::compute(const cv::Mat& image, std::span<cv::KeyPoint> keypoints) const {
  if (image.type() != CV_8UC1) {
    throw std::invalid_argument("intensity centroid: the image must be CV_8UC1");
  }
  for (cv::KeyPoint& kp : keypoints) {
    const int cx = cvRound(kp.pt.x), cy = cvRound(kp.pt.y);
    if (cx < radius_ || cy < radius_ || cx >= image.cols - radius_ || cy >= image.rows - radius_) {
      throw std::invalid_argument(
          fmt::format("intensity centroid: keypoint ({}, {}) is closer than {} px to the border of "
                      "the {}x{} image",
                      kp.pt.x, kp.pt.y, radius_, image.cols, image.rows));
    }
    kp.angle = angleAt(image, kp.pt);
  }
}

}  // namespace edgeslam
