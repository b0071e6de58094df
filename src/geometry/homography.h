#pragma once
// Planar homography between two views: x2 ~ H21 * x1 (homogeneous undistorted pixels).
// Normalised DLT (Hartley-Zisserman alg. 4.2), RANSAC on pre-drawn sets scored by symmetric
// transfer error, and decomposition into motion candidates.
#include <Eigen/Core>
#include <optional>
#include <span>
#include <vector>

#include "geometry/ransac_sampling.h"
#include "geometry/se3.h"
#include "geometry/two_view_score.h"

namespace edgeslam {

// Least-squares normalised DLT from >= 4 matches; nullopt when degenerate (e.g. collinear points).
// Throws std::invalid_argument on mismatched sizes or non-finite input.
std::optional<Eigen::Matrix3d> estimateHomographyDlt(std::span<const Eigen::Vector2d> points1,
                                                     std::span<const Eigen::Vector2d> points2);

// Symmetric transfer error gated at chi2::k2Dof95 per direction.
TwoViewScore scoreHomography(const Eigen::Matrix3d& H21, std::span<const Eigen::Vector2d> points1,
                             std::span<const Eigen::Vector2d> points2, double sigma_px);

struct HomographyEstimate {
  bool valid = false;
  Eigen::Matrix3d H21 = Eigen::Matrix3d::Identity();
  TwoViewScore score;
};

// One model per sample set from its first four indices, best score wins, then least-squares
// re-fits on the inliers while the score improves.
HomographyEstimate findHomographyRansac(std::span<const Eigen::Vector2d> points1,
                                        std::span<const Eigen::Vector2d> points2,
                                        const SampleSets& sample_sets, double sigma_px);

struct HomographyMotion {
  SE3d cam2_from_cam1;           // translation has unit norm (zero for a pure rotation)
  Eigen::Vector3d plane_normal;  // in camera 1
};

// Motion candidates (up to four) from a homography between views sharing the calibration K.
std::vector<HomographyMotion> decomposeHomography(const Eigen::Matrix3d& H21,
                                                  const Eigen::Matrix3d& K);

}  // namespace edgeslam
