#pragma once
// Self-calibration: a bundle adjustment that also estimates the camera's focal length and radial
// distortion from the keypoint observations themselves (no ground truth), as structure-from-motion
// tools refine intrinsics in their bundle adjustment.
//
// Why: an error of a few pixels at the image border, too small to see in any one frame, bends a
// monocular map wherever the camera turns. On KITTI 07 the dataset's calibration leaves such an
// error (the reprojection error is lowest near k1 = +0.02), and the map's scale drifts by ~20 % in
// the first turn; refining the intrinsics over the finished map takes that drift out again.
//
// The problem's observations are keypoints undistorted with `camera` (as the map stores them).
// They are mapped back to raw pixels through camera's own distortion, and the refined model
// (focal scale s, k1, k2; the principal point and the tangential and k3 terms stay as given)
// projects into the raw image. Depth observations keep their disparity, bf / depth, scaled with
// the focal length.
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "geometry/camera.h"
#include "optimize/local_bundle_adjustment.h"

namespace edgeslam {

struct IntrinsicsRefinementOptions {
  bool refine_focal = true;
  bool refine_k1 = true;
  bool refine_k2 = false;
  int iterations = 25;  // per pass; a second pass runs without the first pass's outliers
  // The refinement is adopted only if it lowers the reprojection RMS of the inliers by this
  // fraction (a change the data does not ask for is not made) and stays within these bounds.
  double min_rms_gain = 0.004;
  double max_focal_change = 0.08;      // relative
  double max_distortion_change = 0.2;  // of k1 and of k2, from the given values
  // Fewer free keyframes than this see too few directions to tell focal length from structure.
  std::size_t min_keyframes = 8;
  const std::atomic<bool>* cancel = nullptr;
};

struct IntrinsicsRefinementResult {
  bool adopted = false;
  std::string reason;           // why not adopted (empty when adopted)
  CameraIntrinsics intrinsics;  // the refined intrinsics (the input's when not adopted)
  CameraIntrinsics estimate;    // what the data asked for, adopted or not
  double focal_scale = 1.0;
  // Pixels per residual component, both over the observations the given intrinsics keep as
  // inliers (so that the two are comparable).
  double rms_before = 0.0;  // the given intrinsics, after a bundle adjustment with them
  double rms_after = 0.0;   // the refined ones
  int iterations = 0;
  std::size_t inliers = 0;              // observations in the final solve
  std::size_t outliers = 0;             // left out of it (chi-square test, or behind the camera)
  std::vector<SE3d> T_cw;               // per problem keyframe (fixed ones unchanged)
  std::vector<Eigen::Vector3d> points;  // per problem point
};

// "off", or a comma-separated set of focal, k1, k2 (e.g. "focal,k1"): `base` with those refined
// and the others not; nullopt when malformed.
std::optional<IntrinsicsRefinementOptions> parseRefinedIntrinsics(
    std::string_view spec, IntrinsicsRefinementOptions base = {});
bool refinesAnything(const IntrinsicsRefinementOptions& options);

// Throws std::invalid_argument for a malformed problem (as bundleAdjust does) or options.
IntrinsicsRefinementResult refineIntrinsics(const BundleAdjustmentProblem& problem,
                                            const PinholeCamera& camera,
                                            const IntrinsicsRefinementOptions& options = {});

}  // namespace edgeslam
