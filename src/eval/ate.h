#pragma once
// Absolute trajectory error: distances between ground-truth and aligned estimated positions.
#include <Eigen/Core>
#include <vector>

#include "eval/alignment.h"
#include "eval/association.h"
#include "eval/statistics.h"
#include "geometry/sim3.h"

namespace edgeslam {

struct AteResult {
  AlignMode align = AlignMode::kSe3;
  Sim3d alignment;                 // maps the estimate into the ground-truth frame
  ErrorStatistics translation;     // metres
  std::vector<double> errors;      // per pair, metres, in the order of the pairs
  std::vector<double> timestamps;  // ground-truth time of each pair
  std::vector<Eigen::Vector3d> gt_positions;
  std::vector<Eigen::Vector3d> aligned_est_positions;
};

// Throws EvalError when there are too few pairs for the alignment.
AteResult computeAte(const PosePairs& pairs, AlignMode align);

}  // namespace edgeslam
