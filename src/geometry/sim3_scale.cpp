#include "geometry/sim3_scale.h"

#include <algorithm>
#include <vector>

namespace edgeslam {
namespace {

double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace

std::optional<double> cameraBaselineOverRange(const Sim3d& cam1_from_cam2,
                                              std::span<const Sim3Match> matches) {
  std::vector<double> ranges;
  ranges.reserve(matches.size());
  for (const Sim3Match& m : matches) ranges.push_back(m.point1.norm());
  if (ranges.empty()) return std::nullopt;
  const double range = median(std::move(ranges));
  if (!(range > 0.0)) return std::nullopt;
  return cam1_from_cam2.translation().norm() / range;
}

std::optional<double> scaleFromRanges(const Sim3d& cam1_from_cam2,
                                      std::span<const Sim3Match> matches) {
  const Eigen::Vector3d centre2 = cam1_from_cam2.translation();
  std::vector<double> ratios;
  ratios.reserve(matches.size());
  for (const Sim3Match& m : matches) {
    const double range2 = m.point2.norm();
    if (range2 > 0.0) ratios.push_back((m.point1 - centre2).norm() / range2);
  }
  if (ratios.empty()) return std::nullopt;
  return median(std::move(ratios));
}

}  // namespace edgeslam
