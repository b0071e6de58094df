#include "features/rotation_histogram.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {

RotationHistogram::RotationHistogram(int bins) {
  if (bins < 1) {
    throw std::invalid_argument(
        fmt::format("rotation histogram: bins must be at least 1 (got {})", bins));
  }
  bins_.resize(bins);
}

int RotationHistogram::binOf(float angle1_deg, float angle2_deg) const {
  double difference = std::fmod(static_cast<double>(angle2_deg) - angle1_deg, 360.0);
  if (difference < 0.0) difference += 360.0;
  const int n = static_cast<int>(bins_.size());
  const int bin = static_cast<int>(difference * n / 360.0);
  return std::clamp(bin, 0, n - 1);
}

void RotationHistogram::add(float angle1_deg, float angle2_deg, int id) {
  if (!std::isfinite(angle1_deg) || !std::isfinite(angle2_deg)) {
    throw std::invalid_argument(fmt::format(
        "rotation histogram: non-finite angle ({}, {}) for match {}", angle1_deg, angle2_deg, id));
  }
  bins_[binOf(angle1_deg, angle2_deg)].push_back(id);
}

std::vector<bool> RotationHistogram::keptBins(double min_share) const {
  std::vector<int> order(bins_.size());
  for (int i = 0; i < static_cast<int>(order.size()); ++i) order[i] = i;
  const int top = std::min<int>(3, static_cast<int>(order.size()));
  std::partial_sort(order.begin(), order.begin() + top, order.end(), [&](int a, int b) {
    return bins_[a].size() > bins_[b].size() || (bins_[a].size() == bins_[b].size() && a < b);
  });
  std::vector<bool> kept(bins_.size(), false);
  const double fullest = static_cast<double>(bins_[order[0]].size());
  for (int k = 0; k < top; ++k) {
    const double count = static_cast<double>(bins_[order[k]].size());
    if (count > 0.0 && (k == 0 || count >= min_share * fullest)) kept[order[k]] = true;
  }
  return kept;
}

std::vector<int> RotationHistogram::inconsistent(double min_share) const {
  const std::vector<bool> kept = keptBins(min_share);
  std::vector<int> ids;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    if (!kept[b]) ids.insert(ids.end(), bins_[b].begin(), bins_[b].end());
  }
  return ids;
}

std::vector<int> RotationHistogram::consistent(double min_share) const {
  const std::vector<bool> kept = keptBins(min_share);
  std::vector<int> ids;
  for (std::size_t b = 0; b < bins_.size(); ++b) {
    if (kept[b]) ids.insert(ids.end(), bins_[b].begin(), bins_[b].end());
  }
  return ids;
}

}  // namespace edgeslam
