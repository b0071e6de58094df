#include "adapt/keyframe_config.h"

#include <fmt/format.h>

#include <cmath>
#include <limits>
#include <stdexcept>

namespace edgeslam {

std::string KeyframeConfig::describe() const {
  return fmt::format("fmin {} fmax {} alpha {:g} beta {:g} levels {} nms {:g}", fmin, fmax, alpha,
                     beta, pyramid_levels, nms_threshold);
}

const std::array<AdaptationRow, kAdaptationRows>& adaptationTable() {
  static const std::array<AdaptationRow, kAdaptationRows> table{{
      {0.0, 10.0, {10, 40, 0.3, 0.9, 8, 0.8}},
      {10.0, 15.0, {20, 50, 0.3, 0.9, 6, 0.8}},
      {15.0, 35.0, {20, 60, 0.4, 0.9, 6, 0.8}},
      {35.0, 50.0, {30, 70, 0.5, 0.8, 4, 0.7}},
      {50.0, std::numeric_limits<double>::infinity(), {40, 80, 0.5, 0.7, 4, 0.6}},
  }};
  return table;
}

std::size_t adaptationRowFor(double n_ms) {
  if (std::isnan(n_ms)) throw std::invalid_argument("network time N is NaN");
  const auto& table = adaptationTable();
  for (std::size_t row = 0; row + 1 < table.size(); ++row) {
    if (n_ms <= table[row].n_high_ms) return row;
  }
  return table.size() - 1;
}

}  // namespace edgeslam
