#include "geometry/point_normalization.h"

#include <cmath>
#include <stdexcept>

namespace edgeslam {

NormalizedPoints normalizePoints(const std::vector<Eigen::Vector2d>& points) {
  if (points.empty()) throw std::invalid_argument("normalizePoints: no points");
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& p : points) centroid += p;
  centroid /= static_cast<double>(points.size());

  double mean_distance = 0.0;
  for (const auto& p : points) mean_distance += (p - centroid).norm();
  mean_distance /= static_cast<double>(points.size());
  if (!(mean_distance > 1e-12) || !std::isfinite(mean_distance)) {
    throw std::invalid_argument("normalizePoints: points coincide or are not finite");
  }

  const double s = std::sqrt(2.0) / mean_distance;
  NormalizedPoints out;
  out.T << s, 0.0, -s * centroid.x(), 0.0, s, -s * centroid.y(), 0.0, 0.0, 1.0;
  out.points.reserve(points.size());
  for (const auto& p : points) out.points.emplace_back(s * (p - centroid));
  return out;
}

}  // namespace edgeslam
