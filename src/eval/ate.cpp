#include "eval/ate.h"

namespace edgeslam {

AteResult computeAte(const PosePairs& pairs, AlignMode align) {
  AteResult result;
  result.align = align;
  result.alignment = alignPairs(pairs, align);
  result.errors.reserve(pairs.size());
  for (const PosePair& pair : pairs) {
    const Eigen::Vector3d aligned = result.alignment * pair.est.translation();
    result.gt_positions.push_back(pair.gt.translation());
    result.aligned_est_positions.push_back(aligned);
    result.timestamps.push_back(pair.gt_timestamp);
    result.errors.push_back((aligned - pair.gt.translation()).norm());
  }
  result.translation = computeStatistics(result.errors);
  return result;
}

}  // namespace edgeslam
