#pragma once
// Least-squares alignment of estimated positions to ground truth (Umeyama 1991; for the rigid case
// the same solution as Horn's closed form that the TUM benchmark uses).
#include <Eigen/Core>
#include <string>
#include <vector>

#include "eval/association.h"
#include "geometry/sim3.h"

namespace edgeslam {

// none: compare as is; se3: rotation + translation (RGB-D, stereo); sim3: also scale (monocular).
enum class AlignMode { kNone, kSe3, kSim3 };

std::string toString(AlignMode mode);
// Accepts none|se3|sim3; throws EvalError otherwise.
AlignMode parseAlignMode(const std::string& name);

// Smallest number of pairs each mode accepts.
std::size_t minimumPairsForAlignment(AlignMode mode);

// The transform S (scale 1 unless sim3) minimising sum |gt_i - S est_i|^2.
// Throws EvalError naming the problem when there are too few pairs, the estimate's positions are
// all equal (scale undefined), or the sizes differ.
Sim3d alignPositions(const std::vector<Eigen::Vector3d>& est,
                     const std::vector<Eigen::Vector3d>& gt, AlignMode mode);

// Positions of the pairs, for alignPositions.
std::vector<Eigen::Vector3d> gtPositions(const PosePairs& pairs);
std::vector<Eigen::Vector3d> estPositions(const PosePairs& pairs);

// alignPositions on the pairs' positions.
Sim3d alignPairs(const PosePairs& pairs, AlignMode mode);

}  // namespace edgeslam
