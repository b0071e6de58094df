#include "semantic/mask_query.h"

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

cv::Mat1b dilated(const cv::Mat1b& mask, int margin_px) {
  if (margin_px <= 0) return mask;
  cv::Mat1b out;
  const cv::Mat kernel =
      cv::getStructuringElement(cv::MORPH_RECT, cv::Size(2 * margin_px + 1, 2 * margin_px + 1));
  cv::dilate(mask, out, kernel);
  return out;
}

template <typename PointOf>
std::vector<int> keepOutside(std::size_t count, PointOf point_of, const cv::Mat1b& mask,
                             int margin_px) {
  if (margin_px < 0) {
    throw std::invalid_argument("mask margin must be >= 0, got " + std::to_string(margin_px));
  }
  std::vector<int> kept;
  kept.reserve(count);
  if (mask.empty() || cv::countNonZero(mask) == 0) {
    for (std::size_t i = 0; i < count; ++i) kept.push_back(static_cast<int>(i));
    return kept;
  }
  const cv::Mat1b grown = dilated(mask, margin_px);
  for (std::size_t i = 0; i < count; ++i) {
    const cv::Point2f p = point_of(i);
    const int x = cvFloor(p.x), y = cvFloor(p.y);
    const bool inside_image = x >= 0 && y >= 0 && x < grown.cols && y < grown.rows;
    if (!inside_image || grown(y, x) == 0) kept.push_back(static_cast<int>(i));
  }
  return kept;
}

}  // namespace

bool insideMask(const cv::Mat1b& mask, cv::Point2f point, int margin_px) {
  if (mask.empty()) return false;
  const int x = cvFloor(point.x), y = cvFloor(point.y);
  const int margin = std::max(margin_px, 0);
  const cv::Rect window = cv::Rect(x - margin, y - margin, 2 * margin + 1, 2 * margin + 1) &
                          cv::Rect(0, 0, mask.cols, mask.rows);
  if (window.empty()) return false;
  if (margin == 0) return mask(y, x) != 0;
  for (int row = window.y; row < window.y + window.height; ++row) {
    const std::uint8_t* pixels = mask.ptr<std::uint8_t>(row);
    for (int col = window.x; col < window.x + window.width; ++col) {
      if (pixels[col] != 0) return true;
    }
  }
  return false;
}

std::vector<int> indicesOutsideMask(const std::vector<cv::Point2f>& points, const cv::Mat1b& mask,
                                    int margin_px) {
  return keepOutside(
      points.size(), [&](std::size_t i) { return points[i]; }, mask, margin_px);
}

std::vector<int> indicesOutsideMask(const std::vector<cv::KeyPoint>& keypoints,
                                    const cv::Mat1b& mask, int margin_px) {
  return keepOutside(
      keypoints.size(), [&](std::size_t i) { return keypoints[i].pt; }, mask, margin_px);
}

}  // namespace edgeslam
