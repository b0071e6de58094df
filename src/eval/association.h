#pragma once
// Pairing of estimated and ground-truth poses, by timestamp (TUM benchmark rule) or by index.
#include <cstddef>
#include <vector>

#include "geometry/se3.h"
#include "io/trajectory.h"

namespace edgeslam {

struct PosePair {
  double gt_timestamp = 0.0;
  double est_timestamp = 0.0;
  std::size_t gt_index = 0;   // position in the ground-truth trajectory as given
  std::size_t est_index = 0;  // position in the estimated trajectory as given
  SE3d gt;                    // camera-to-world
  SE3d est;                   // camera-to-world, in the estimate's own frame
};

using PosePairs = std::vector<PosePair>;

inline constexpr double kDefaultMaxTimeDifference = 0.02;  // seconds

// TUM benchmark association: every (gt, est) pair with |t_gt - t_est| < max_dt is a candidate;
// candidates are taken closest-in-time first (ties by gt time, then est time), each pose used at
// most once. The result is sorted by ground-truth time. Inputs need not be sorted.
// Throws EvalError when max_dt is not positive; an empty result is returned as is.
PosePairs associateByTimestamp(const Trajectory& gt, const Trajectory& est,
                               double max_dt = kDefaultMaxTimeDifference);

// Pairs pose i with pose i (KITTI files, one line per frame). Throws EvalError when the lengths
// differ.
PosePairs associateByIndex(const Trajectory& gt, const Trajectory& est);

}  // namespace edgeslam
