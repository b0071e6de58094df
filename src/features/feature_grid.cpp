#include "features/feature_grid.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {

FeatureGrid::FeatureGrid(const PinholeCamera::Bounds& bounds,
                         std::span<const cv::KeyPoint> keypoints, double cell_size) {
  const bool finite = std::isfinite(bounds.min_x) && std::isfinite(bounds.max_x) &&
                      std::isfinite(bounds.min_y) && std::isfinite(bounds.max_y);
  if (!finite || bounds.max_x <= bounds.min_x || bounds.max_y <= bounds.min_y) {
    throw std::invalid_argument(fmt::format("feature grid: bad bounds x [{}, {}] y [{}, {}]",
                                            bounds.min_x, bounds.max_x, bounds.min_y,
                                            bounds.max_y));
  }
  if (!std::isfinite(cell_size) || cell_size <= 0.0) {
    throw std::invalid_argument(
        fmt::format("feature grid: cell_size must be positive (got {})", cell_size));
  }
  min_x_ = bounds.min_x;
  min_y_ = bounds.min_y;
  inv_cell_ = 1.0 / cell_size;
  cols_ = std::max(1, static_cast<int>(std::ceil((bounds.max_x - bounds.min_x) * inv_cell_)));
  rows_ = std::max(1, static_cast<int>(std::ceil((bounds.max_y - bounds.min_y) * inv_cell_)));

  const int n = static_cast<int>(keypoints.size());
  std::vector<int> cell_of(n);
  cell_start_.assign(static_cast<std::size_t>(cols_) * rows_ + 1, 0);
  for (int i = 0; i < n; ++i) {
    const cv::Point2f& p = keypoints[i].pt;
    if (!std::isfinite(p.x) || !std::isfinite(p.y)) {
      throw std::invalid_argument(
          fmt::format("feature grid: keypoint {} has a non-finite position ({}, {})", i, p.x, p.y));
    }
    cell_of[i] = cellRow(p.y) * cols_ + cellColumn(p.x);
    ++cell_start_[cell_of[i] + 1];
  }
  for (std::size_t c = 1; c < cell_start_.size(); ++c) cell_start_[c] += cell_start_[c - 1];
  points_.resize(n);
  std::vector<int> fill(cell_start_.begin(), cell_start_.end() - 1);
  for (int i = 0; i < n; ++i) {
    const cv::KeyPoint& kp = keypoints[i];
    points_[fill[cell_of[i]]++] = {kp.pt.x, kp.pt.y, kp.octave, i};
  }
}

int FeatureGrid::cellColumn(float x) const {
  const double c = std::floor((x - min_x_) * inv_cell_);
  return static_cast<int>(std::clamp(c, 0.0, static_cast<double>(cols_ - 1)));
}

int FeatureGrid::cellRow(float y) const {
  const double r = std::floor((y - min_y_) * inv_cell_);
  return static_cast<int>(std::clamp(r, 0.0, static_cast<double>(rows_ - 1)));
}

std::vector<int> FeatureGrid::featuresInArea(float x, float y, float radius, int min_level,
                                             int max_level) const {
  std::vector<int> out;
  featuresInArea(x, y, radius, min_level, max_level, out);
  return out;
}

void FeatureGrid::featuresInArea(float x, float y, float radius, int min_level, int max_level,
                                 std::vector<int>& out) const {
  out.clear();
  if (points_.empty() || !(radius >= 0.f) || !std::isfinite(x) || !std::isfinite(y)) return;
  // Clamping keeps border cells (which also hold the points outside the bounds) in reach.
  const int c0 = cellColumn(x - radius), c1 = cellColumn(x + radius);
  const int r0 = cellRow(y - radius), r1 = cellRow(y + radius);
  const bool check_min = min_level >= 0, check_max = max_level >= 0;
  for (int r = r0; r <= r1; ++r) {
    for (int c = c0; c <= c1; ++c) {
      const int cell = r * cols_ + c;
      for (int k = cell_start_[cell]; k < cell_start_[cell + 1]; ++k) {
        const Entry& e = points_[k];
        if (check_min && e.level < min_level) continue;
        if (check_max && e.level > max_level) continue;
        if (std::abs(e.x - x) <= radius && std::abs(e.y - y) <= radius) out.push_back(e.index);
      }
    }
  }
}

}  // namespace edgeslam
