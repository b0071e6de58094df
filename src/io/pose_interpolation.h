#pragma once
// Ground truth at a frame's time from a trajectory sampled at other times.
#include <optional>

#include "io/trajectory.h"

namespace edgeslam {

// Default tolerance for pairing a frame with ground-truth samples (the TUM benchmark's 0.02 s).
inline constexpr double kDefaultPoseTimeTolerance = 0.02;

// Pose at `time` from a trajectory sorted by time:
// - a sample within 1 microsecond of `time` is returned as is;
// - otherwise the two samples bracketing `time` are interpolated (translation linearly, rotation
//   by slerp) when both lie within `max_gap` seconds of `time`;
// - otherwise (outside the trajectory, or a gap in it) nullopt: no extrapolation.
std::optional<SE3d> interpolatePose(const Trajectory& sorted, double time, double max_gap);

// Sorts by timestamp (stable) so that interpolatePose can search it.
void sortByTime(Trajectory& trajectory);

}  // namespace edgeslam
