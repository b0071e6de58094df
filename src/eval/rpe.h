#pragma once
// Relative pose error: how well the estimate reproduces the motion between two poses a fixed
// delta apart. For poses i < j: E = (gt_i^-1 gt_j)^-1 (est_i^-1 est_j); the translation error is
// |t(E)| in metres, the rotation error the angle of R(E) in degrees.
#include <cstddef>
#include <string>
#include <vector>

#include "eval/alignment.h"
#include "eval/association.h"
#include "eval/statistics.h"

namespace edgeslam {

enum class DeltaUnit { kFrames, kSeconds, kMetres };

std::string toString(DeltaUnit unit);
// Accepts frames|seconds|metres (also f, s, m, meters); throws EvalError otherwise.
DeltaUnit parseDeltaUnit(const std::string& name);

struct RpeOptions {
  double delta = 1.0;
  DeltaUnit unit = DeltaUnit::kFrames;
  // Only the scale of the alignment matters (relative motion is invariant to a rigid transform of
  // the whole trajectory): sim3 rescales the estimate's translations, se3 and none leave them.
  AlignMode align = AlignMode::kNone;
};

struct RelativeError {
  std::size_t first = 0;   // index into the pairs
  std::size_t second = 0;  // index into the pairs
  double translation_m = 0.0;
  double rotation_deg = 0.0;
};

struct RpeResult {
  RpeOptions options;
  double scale = 1.0;           // applied to the estimate's translations
  ErrorStatistics translation;  // metres
  ErrorStatistics rotation;     // degrees
  std::vector<RelativeError> errors;
};

// Pose i is paired with i + delta (frames), or with the first pose whose ground-truth time
// (seconds) or path length along the ground truth (metres) is at least delta beyond pose i's.
// Pairs must be in time order. Throws EvalError when delta is not positive (not a whole number
// for frames) or no pose pair is delta apart.
RpeResult computeRpe(const PosePairs& pairs, const RpeOptions& options);

}  // namespace edgeslam
