#pragma once
// Bundle adjustment of keyframe poses (T_cw) and map points over keypoint observations; the
// local-mapping window (some keyframes fixed) and, with all keyframes, global BA in the
// background (cancellable when a new keyframe arrives).
#include <Eigen/Core>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "geometry/se3.h"
#include "optimize/camera_projection.h"
#include "optimize/chi2_thresholds.h"
#include "optimize/solver_control.h"

namespace edgeslam {

struct BAKeyFrame {
  std::uint64_t id = 0;
  SE3d T_cw;
  bool fixed = false;  // seen by the window's points but not optimised (or the gauge keyframes)
};

struct BAPoint {
  std::uint64_t id = 0;
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // world frame
  bool fixed = false;
};

struct BAObservation {
  std::size_t keyframe = 0;                         // index into keyframes
  std::size_t point = 0;                            // index into points
  Eigen::Vector2d pixel = Eigen::Vector2d::Zero();  // undistorted keypoint
  std::optional<double> right_u;                    // stereo / RGB-D virtual right coordinate
  double inv_sigma2 = 1.0;
};

struct BundleAdjustmentProblem {
  CameraProjection camera;
  std::vector<BAKeyFrame> keyframes;
  std::vector<BAPoint> points;
  std::vector<BAObservation> observations;
};

struct BundleAdjustmentOptions {
  int first_pass_iterations = 5;
  // After the first pass, observations over the chi2 threshold (or behind their camera) are left
  // out and the rest optimised again.
  bool second_pass = true;
  int second_pass_iterations = 10;
  bool robust_in_second_pass = false;
  double chi2_mono = kChi2Mono95;
  double chi2_stereo = kChi2Stereo95;
  // Wall-clock budget for the whole run in seconds; 0 means none.
  double max_time_s = 0.0;
  // Checked after every iteration (and before each pass): when true the run stops, keeping the
  // state of the last accepted iteration.
  const std::atomic<bool>* cancel = nullptr;
  IterationHook on_iteration;
  // Dense Schur complement up to this many free keyframes, sparse (SuiteSparse) beyond.
  int dense_schur_max_keyframes = 40;
  int num_threads = 1;

  static BundleAdjustmentOptions local() { return {}; }
  // Global BA: every keyframe, more iterations, robust throughout, no second pass.
  static BundleAdjustmentOptions global() {
    BundleAdjustmentOptions options;
    options.first_pass_iterations = 10;
    options.second_pass = false;
    return options;
  }
};

struct BundleAdjustmentResult {
  std::vector<SE3d> T_cw;               // one per keyframe (fixed ones unchanged)
  std::vector<Eigen::Vector3d> points;  // one per point
  std::vector<std::size_t> outliers;    // indices of observations to remove, at the final state
  bool cancelled = false;
  bool timed_out = false;
  int iterations = 0;
  // Root mean square of the whitened residual components (pixels at pyramid level 0): before over
  // every observation in front of its camera, after over the observations that are not outliers.
  double rms_before = 0.0;
  double rms_after = 0.0;
};

// Throws std::invalid_argument, prefixed with `caller`, naming the bad keyframe / point /
// observation.
void validateBundleAdjustmentProblem(const BundleAdjustmentProblem& problem,
                                     const std::string& caller);

// Throws std::invalid_argument naming the bad keyframe / point / observation.
BundleAdjustmentResult bundleAdjust(const BundleAdjustmentProblem& problem,
                                    const BundleAdjustmentOptions& options = {});

}  // namespace edgeslam
