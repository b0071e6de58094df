#pragma once
// Chi-square quantiles used as inlier thresholds on squared residuals normalised by the
// measurement variance (residual^2 / sigma^2). One place so every solver agrees.
namespace edgeslam::chi2 {

// 95 % quantiles.
inline constexpr double k1Dof95 = 3.841;  // point-to-line distance (epipolar constraint)
inline constexpr double k2Dof95 = 5.991;  // point-to-point distance in an image
inline constexpr double k3Dof95 = 7.815;  // stereo / RGB-D reprojection (u, v, u_right)
// 99 % quantile, 2 dof: the looser gate used for Sim(3) loop candidates.
inline constexpr double k2Dof99 = 9.210;
// Reprojection gate for triangulated points during two-view initialisation (2 px at sigma = 1).
inline constexpr double kTriangulationGate = 4.0;

}  // namespace edgeslam::chi2
