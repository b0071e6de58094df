#pragma once
// A perceptually ordered dark-blue -> teal -> green -> yellow colormap for error values.
#include <string>

namespace edgeslam {

struct Rgb {
  double r = 0.0;  // 0..1
  double g = 0.0;
  double b = 0.0;
};

// t in [0, 1] (clamped): piecewise-linear through five anchor colours in the style of viridis.
Rgb errorColormap(double t);

// "#rrggbb".
std::string toHex(const Rgb& colour);

}  // namespace edgeslam
