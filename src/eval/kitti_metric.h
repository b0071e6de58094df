#pragma once
// The KITTI odometry benchmark metric (devkit `evaluate_odometry`), written from its description:
//  - distances: d_0 = 0, d_i = d_{i-1} + |t_gt_i - t_gt_{i-1}| (path length along the ground
//    truth, over every frame);
//  - segments: for every first frame f = 0, 10, 20, ... and every length L in {100, ..., 800} m,
//    the last frame l is the first frame with d_l > d_f + L (strictly greater); when the
//    sequence ends before that, the segment does not count;
//  - error: E = (est_f^-1 est_l)^-1 (gt_f^-1 gt_l);
//    t_err = |t(E)| / L and r_err = acos(clamp((trace R(E) - 1) / 2, -1, 1)) / L, both divided by
//    the nominal length L (not by d_l - d_f);
//  - averages: per length, the mean over that length's segments; overall, the mean over all
//    segments of all lengths (so the long lengths, having fewer segments, weigh a little less).
// The devkit prints t in % (x100) and r in deg/m; here r is reported in deg/100 m (x100 more),
// the unit of the KITTI leaderboard and of most papers.
// Poses are paired by index; the devkit does not align. With sim3 alignment (monocular) the
// estimate's translations are multiplied by the least-squares scale first; a rigid alignment of
// the whole trajectory would not change any relative pose, so se3 equals none here.
#include <cstddef>
#include <vector>

#include "eval/alignment.h"
#include "eval/association.h"

namespace edgeslam {

struct KittiOptions {
  std::size_t step_frames = 10;
  std::vector<double> lengths_m = {100, 200, 300, 400, 500, 600, 700, 800};
  AlignMode align = AlignMode::kNone;
};

struct KittiSegmentError {
  std::size_t first_frame = 0;
  std::size_t last_frame = 0;
  double length_m = 0.0;
  double t_err = 0.0;            // translation error / length (ratio)
  double r_err_rad_per_m = 0.0;  // rotation error / length
};

struct KittiLengthError {
  double length_m = 0.0;
  std::size_t segments = 0;
  double t_rel_percent = 0.0;
  double r_rel_deg_per_100m = 0.0;
};

struct KittiResult {
  KittiOptions options;
  double scale = 1.0;  // applied to the estimate's translations (sim3 only)
  std::size_t frames = 0;
  double path_length_m = 0.0;  // ground truth
  double t_rel_percent = 0.0;
  double r_rel_deg_per_100m = 0.0;
  std::vector<KittiLengthError> per_length;  // lengths with at least one segment
  std::vector<KittiSegmentError> segments;
};

// Path length along the ground truth up to each pair (d_i above).
std::vector<double> trajectoryDistances(const PosePairs& pairs);

// Throws EvalError when no segment fits (ground-truth path shorter than the shortest length) or
// the options are invalid.
KittiResult computeKittiMetric(const PosePairs& pairs, const KittiOptions& options = {});

}  // namespace edgeslam
