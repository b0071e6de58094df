#include "io/pose_interpolation.h"

#include <algorithm>
#include <cmath>

namespace edgeslam {

std::optional<SE3d> interpolatePose(const Trajectory& sorted, double time, double max_gap) {
  constexpr double kSameTime = 1e-6;
  const auto after =
      std::lower_bound(sorted.begin(), sorted.end(), time,
                       [](const StampedPose& sample, double t) { return sample.timestamp < t; });
  if (after != sorted.end() && after->timestamp - time <= kSameTime) return after->pose;
  if (after == sorted.begin()) return std::nullopt;
  const auto before = std::prev(after);
  if (time - before->timestamp <= kSameTime) return before->pose;
  if (after == sorted.end()) return std::nullopt;
  if (time - before->timestamp > max_gap || after->timestamp - time > max_gap) return std::nullopt;

  const double s = (time - before->timestamp) / (after->timestamp - before->timestamp);
  const SE3d& a = before->pose;
  const SE3d& b = after->pose;
  const Eigen::Vector3d translation = (1.0 - s) * a.translation() + s * b.translation();
  // Eigen's slerp takes the shorter arc, so q and -q samples interpolate correctly.
  return SE3d(a.rotation().slerp(s, b.rotation()), translation);
}

void sortByTime(Trajectory& trajectory) {
  std::stable_sort(
      trajectory.begin(), trajectory.end(),
      [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
}

}  // namespace edgeslam
