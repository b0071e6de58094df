#include "features/fast_grid_detector.h"

#include <fmt/format.h>

#include <algorithm>
#include <opencv2/features2d.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

constexpr int kFastRadius = 3;

// FAST on `area` (plus the 3-pixel margin its circle needs), keypoints in image coordinates.
void fastIn(const cv::Mat& image, const cv::Rect& area, int threshold,
            std::vector<cv::KeyPoint>& out) {
  const cv::Rect padded(area.x - kFastRadius, area.y - kFastRadius, area.width + 2 * kFastRadius,
                        area.height + 2 * kFastRadius);
  out.clear();
  cv::FAST(image(padded), out, threshold, /*nonmaxSuppression=*/true,
           cv::FastFeatureDetector::TYPE_9_16);
  for (cv::KeyPoint& kp : out) {
    kp.pt.x += static_cast<float>(padded.x);
    kp.pt.y += static_cast<float>(padded.y);
  }
}

}  // namespace

void detectFastInGrid(const cv::Mat& image, const cv::Rect& region, const FastGridOptions& options,
                      std::vector<cv::KeyPoint>& keypoints) {
  if (image.type() != CV_8UC1) {
    throw std::invalid_argument("FAST grid: the image must be CV_8UC1");
  }
  if (options.cell_size < 1 || options.low_threshold < 1 ||
      options.high_threshold < options.low_threshold) {
    throw std::invalid_argument(fmt::format(
        "FAST grid: need cell_size >= 1 and 1 <= low_threshold <= high_threshold (got {}, {}, {})",
        options.cell_size, options.low_threshold, options.high_threshold));
  }
  if (region.empty()) return;
  const cv::Rect inner(kFastRadius, kFastRadius, image.cols - 2 * kFastRadius,
                       image.rows - 2 * kFastRadius);
  if ((region & inner) != region) {
    throw std::invalid_argument(fmt::format(
        "FAST grid: region ({}, {}, {}x{}) must keep {} px from the border of the "
        "{}x{} image",
        region.x, region.y, region.width, region.height, kFastRadius, image.cols, image.rows));
  }

  std::vector<cv::KeyPoint> found;
  fastIn(image, region, options.high_threshold, found);

  const int cols = std::max(1, region.width / options.cell_size);
  const int rows = std::max(1, region.height / options.cell_size);
  // Pixel x (region coordinates) is in cell floor(x * cols / width), so cell c starts at
  // ceil(c * width / cols).
  auto cellEdge = [](int index, int length, int count) {
    return (index * length + count - 1) / count;
  };
  std::vector<int> per_cell(static_cast<std::size_t>(cols) * rows, 0);
  for (const cv::KeyPoint& kp : found) {
    const int x = static_cast<int>(kp.pt.x) - region.x;
    const int y = static_cast<int>(kp.pt.y) - region.y;
    const int c = std::min(cols - 1, x * cols / region.width);
    const int r = std::min(rows - 1, y * rows / region.height);
    ++per_cell[static_cast<std::size_t>(r) * cols + c];
  }
  keypoints.insert(keypoints.end(), found.begin(), found.end());

  if (options.low_threshold == options.high_threshold) return;
  // Horizontal runs of empty cells are searched with one call: FAST's cost per call and its
  // 3-pixel margin are paid once per run instead of once per cell.
  for (int r = 0; r < rows; ++r) {
    const int* row = per_cell.data() + static_cast<std::size_t>(r) * cols;
    for (int c = 0; c < cols;) {
      if (row[c] > 0) {
        ++c;
        continue;
      }
      int end = c + 1;
      while (end < cols && row[end] == 0) ++end;
      const int x0 = cellEdge(c, region.width, cols), x1 = cellEdge(end, region.width, cols);
      const int y0 = cellEdge(r, region.height, rows), y1 = cellEdge(r + 1, region.height, rows);
      fastIn(image, cv::Rect(region.x + x0, region.y + y0, x1 - x0, y1 - y0), options.low_threshold,
             found);
      keypoints.insert(keypoints.end(), found.begin(), found.end());
      c = end;
    }
  }
}

}  // namespace edgeslam
