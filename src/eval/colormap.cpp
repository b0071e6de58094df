#include "eval/colormap.h"

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>

namespace edgeslam {

Rgb errorColormap(double t) {
  // Anchor colours at t = 0, 0.25, 0.5, 0.75, 1 (viridis' dark violet, blue, teal, green, yellow).
  static constexpr std::array<Rgb, 5> kAnchors = {{{0.267, 0.005, 0.329},
                                                   {0.231, 0.322, 0.545},
                                                   {0.129, 0.569, 0.549},
                                                   {0.369, 0.788, 0.384},
                                                   {0.992, 0.906, 0.145}}};
  if (!std::isfinite(t)) t = 0.0;
  const double x = std::clamp(t, 0.0, 1.0) * static_cast<double>(kAnchors.size() - 1);
  const auto i = std::min(static_cast<std::size_t>(x), kAnchors.size() - 2);
  const double f = x - static_cast<double>(i);
  const Rgb& a = kAnchors[i];
  const Rgb& b = kAnchors[i + 1];
  return {a.r + f * (b.r - a.r), a.g + f * (b.g - a.g), a.b + f * (b.b - a.b)};
}

std::string toHex(const Rgb& colour) {
  const auto byte = [](double v) {
    return static_cast<int>(std::lround(255.0 * std::clamp(v, 0.0, 1.0)));
  };
  return fmt::format("#{:02x}{:02x}{:02x}", byte(colour.r), byte(colour.g), byte(colour.b));
}

}  // namespace edgeslam
