#pragma once
// Outlier tests of whitened reprojection residuals, named for the optimisation problems; the values
// live in geometry/chi_square.h so every solver agrees.
#include "geometry/chi_square.h"

namespace edgeslam {

inline constexpr double kChi2Mono95 = chi2::k2Dof95;    // (u, v)
inline constexpr double kChi2Stereo95 = chi2::k3Dof95;  // (u, v, u_right)

}  // namespace edgeslam
