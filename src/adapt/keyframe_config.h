#pragma once
// The configuration tuples of paper Table I: keyframe rules (fmin, fmax, alpha, beta), ORB pyramid
// levels and the segmentation NMS threshold, chosen by the network condition N = L + M/B (ms).
#include <array>
#include <string>

namespace edgeslam {

struct KeyframeConfig {
  int fmin = 20;
  int fmax = 60;
  double alpha = 0.4;
  double beta = 0.9;
  int pyramid_levels = 6;
  double nms_threshold = 0.8;

  bool operator==(const KeyframeConfig&) const = default;
  std::string describe() const;
};

struct AdaptationRow {
  double n_low_ms;   // exclusive
  double n_high_ms;  // inclusive (the last row is open-ended: N >= 300 ms stays there)
  KeyframeConfig config;
};

inline constexpr std::size_t kAdaptationRows = 5;

// Table I, rows in order of increasing N.
const std::array<AdaptationRow, kAdaptationRows>& adaptationTable();

// The row whose interval holds `n_ms`: (0,10] -> 0, (10,15] -> 1, (15,35] -> 2, (35,50] -> 3,
// above 50 -> 4. N <= 0 (an instant link) maps to row 0. Throws std::invalid_argument for NaN.
std::size_t adaptationRowFor(double n_ms);

// The row of the paper's defaults (fmin 20, fmax 60, alpha 0.4, beta 0.9): row 2.
inline constexpr std::size_t kDefaultAdaptationRow = 2;

}  // namespace edgeslam
