#include "features/scale_levels.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {

ScaleLevels::ScaleLevels(int num_levels, double scale_factor) : scale_factor_(scale_factor) {
  if (num_levels < 1) {
    throw std::invalid_argument(
        fmt::format("scale levels: num_levels must be at least 1 (got {})", num_levels));
  }
  if (!std::isfinite(scale_factor) || scale_factor <= 1.0) {
    throw std::invalid_argument(
        fmt::format("scale levels: scale_factor must be greater than 1 (got {})", scale_factor));
  }
  log_scale_factor_ = std::log(scale_factor);
  scale_.resize(num_levels);
  inv_scale_.resize(num_levels);
  sigma2_.resize(num_levels);
  inv_sigma2_.resize(num_levels);
  double s = 1.0;
  for (int level = 0; level < num_levels; ++level) {
    scale_[level] = s;
    inv_scale_[level] = 1.0 / s;
    sigma2_[level] = s * s;
    inv_sigma2_[level] = 1.0 / (s * s);
    s *= scale_factor;
  }
}

int ScaleLevels::predictLevel(double reference_distance, int reference_level,
                              double distance) const {
  if (!(distance > 0.0) || !(reference_distance > 0.0))
    return std::clamp(reference_level, 0, numLevels() - 1);
  const double offset = std::log(reference_distance / distance) / log_scale_factor_;
  const int level = reference_level + static_cast<int>(std::ceil(offset - 1e-9));
  return std::clamp(level, 0, numLevels() - 1);
}

}  // namespace edgeslam
