#include "synth/mask_metrics.h"

#include <cmath>
#include <stdexcept>

namespace edgeslam {

std::optional<double> maskIoU(const cv::Mat1b& predicted, const cv::Mat1b& truth) {
  if (predicted.size() != truth.size()) {
    throw std::invalid_argument("maskIoU: the masks differ in size");
  }
  const cv::Mat1b a = predicted > 0;
  const cv::Mat1b b = truth > 0;
  const int united = cv::countNonZero(a | b);
  if (united == 0) return std::nullopt;
  return static_cast<double>(cv::countNonZero(a & b)) / united;
}

FeaturesOnMask countFeaturesOnMask(const std::vector<cv::Point2f>& points, const cv::Mat1b& mask) {
  FeaturesOnMask counts;
  for (const cv::Point2f& point : points) {
    const int x = static_cast<int>(std::lround(point.x));
    const int y = static_cast<int>(std::lround(point.y));
    if (x < 0 || y < 0 || x >= mask.cols || y >= mask.rows) continue;
    ++counts.total;
    if (mask(y, x) != 0) ++counts.on_mask;
  }
  return counts;
}

}  // namespace edgeslam
