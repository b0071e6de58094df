#pragma once
// Monocular map initialisation from two views (the scheme of the ORB-SLAM paper, Sec. IV, built on
// Hartley-Zisserman): a homography and a fundamental matrix are estimated in parallel by RANSAC on
// the same pre-drawn samples, the model is chosen by R_H = S_H / (S_H + S_F), its motion
// hypotheses are triangulated and a single clear winner with enough parallax is required.
#include <Eigen/Core>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "geometry/se3.h"

namespace edgeslam {

enum class TwoViewModel { kNone, kHomography, kFundamental };
enum class TwoViewFailure {
  kNone,
  kTooFewMatches,       // fewer matches than options.min_matches
  kNoModel,             // neither RANSAC found a model (degenerate points)
  kLowParallax,         // pure rotation or too little translation for the depth
  kTooFewTriangulated,  // fewer good points than options.min_triangulated
  kAmbiguousMotion,     // two motion hypotheses explain the matches about equally well
  kPoorReconstruction,  // too few of the model's inliers triangulate consistently
};
const char* toString(TwoViewModel model);
const char* toString(TwoViewFailure failure);

struct TwoViewOptions {
  int min_matches = 50;
  int ransac_iterations = 200;
  double sigma_px = 1.0;                     // keypoint position noise (std. dev.)
  double homography_ratio_threshold = 0.45;  // choose H when S_H / (S_H + S_F) > this
  int min_triangulated = 50;
  // Enough parallax = at least `parallax_rank` model inliers see the point under min_parallax_deg
  // or more (a median would refuse forward motion, where most points are far and few are close).
  double min_parallax_deg = 1.0;
  int parallax_rank = 50;
  double min_point_parallax_deg = 0.5;  // below it a point is not flagged triangulated
  double max_second_best_ratio = 0.7;   // second-best good count / best good count
  double min_good_fraction = 0.8;       // best good count / model inliers
  bool parallel = true;                 // estimate H and F on two threads
  // Refine the winning motion on the Sampson error before the final triangulation.
  bool refine = true;
  // When F was chosen but does not reconstruct (e.g. a planar scene whose R_H fell just below the
  // threshold because the noise is close to sigma), try the homography; flagged in used_fallback.
  bool fallback_to_homography = true;
  uint64_t seed = 0x5eed;
};

struct TwoViewResult {
  bool success = false;
  TwoViewFailure failure = TwoViewFailure::kNone;
  std::string reason;  // human-readable explanation of the failure (empty on success)
  TwoViewModel model = TwoViewModel::kNone;
  SE3d current_from_reference;  // |t| = 1 on success
  // One entry per match; points are in the reference camera frame and valid where triangulated.
  std::vector<Eigen::Vector3d> points_reference;
  std::vector<char> triangulated;
  // Matches consistent with the chosen model; after refinement, with the refined epipolar
  // geometry (which may add matches the linear model missed).
  std::vector<char> model_inliers;
  int num_triangulated = 0;

  // Diagnostics.
  double score_homography = 0.0;
  double score_fundamental = 0.0;
  double homography_ratio = 0.0;
  int inliers_homography = 0;
  int inliers_fundamental = 0;
  bool used_fallback = false;       // H reconstructed after F, which the score ratio chose, failed
  std::vector<int> candidate_good;  // good points per motion hypothesis, in hypothesis order
  int best_good = 0;
  int second_best_good = 0;
  double median_parallax_deg = 0.0;
  double ranked_parallax_deg = 0.0;  // the parallax_rank-th largest inlier parallax
};

// reference_px / current_px: matched undistorted pixels (same length); K: shared calibration.
// Throws std::invalid_argument on mismatched sizes, non-finite values or bad options/K.
TwoViewResult initializeTwoView(std::span<const Eigen::Vector2d> reference_px,
                                std::span<const Eigen::Vector2d> current_px,
                                const Eigen::Matrix3d& K, const TwoViewOptions& options = {});

// Rescales the baseline and the triangulated points so that their median depth in the reference
// camera is 1. Returns the factor applied, or 0 (and leaves the result untouched) when there is no
// triangulated point in front of the reference camera.
double normalizeToUnitMedianDepth(TwoViewResult& result);

}  // namespace edgeslam
