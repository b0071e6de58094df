#include "eval/kitti_metric.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "eval/eval_error.h"

namespace edgeslam {
namespace {

// The devkit's rotation angle: acos of (trace - 1) / 2, clamped against rounding.
double devkitRotationAngle(const Eigen::Matrix3d& r) {
  const double c = 0.5 * (r.trace() - 1.0);
  return std::acos(std::clamp(c, -1.0, 1.0));
}

constexpr double kRadPerMToDegPer100m = 180.0 / std::numbers::pi * 100.0;

}  // namespace

std::vector<double> trajectoryDistances(const PosePairs& pairs) {
  std::vector<double> d(pairs.size(), 0.0);
  for (std::size_t i = 1; i < pairs.size(); ++i) {
    d[i] = d[i - 1] + (pairs[i].gt.translation() - pairs[i - 1].gt.translation()).norm();
  }
  return d;
}

KittiResult computeKittiMetric(const PosePairs& pairs, const KittiOptions& options) {
  if (options.step_frames == 0) throw EvalError("KITTI metric step must be at least one frame");
  if (options.lengths_m.empty()) throw EvalError("KITTI metric needs at least one segment length");
  for (const double length : options.lengths_m) {
    if (!(length > 0.0))
      throw EvalError(fmt::format("segment length must be positive: {}", length));
  }
  KittiResult result;
  result.options = options;
  result.frames = pairs.size();
  if (options.align == AlignMode::kSim3) result.scale = alignPairs(pairs, AlignMode::kSim3).scale();

  const std::vector<double> dist = trajectoryDistances(pairs);
  result.path_length_m = dist.empty() ? 0.0 : dist.back();

  for (std::size_t first = 0; first < pairs.size(); first += options.step_frames) {
    for (const double length : options.lengths_m) {
      // dist is non-decreasing: the first frame with d > d_first + length.
      const auto it = std::upper_bound(dist.begin() + static_cast<std::ptrdiff_t>(first),
                                       dist.end(), dist[first] + length);
      if (it == dist.end()) continue;
      const auto last = static_cast<std::size_t>(it - dist.begin());
      const SE3d gt_motion = pairs[first].gt.inverse() * pairs[last].gt;
      SE3d est_motion = pairs[first].est.inverse() * pairs[last].est;
      est_motion.setTranslation(result.scale * est_motion.translation());
      const SE3d error = est_motion.inverse() * gt_motion;
      result.segments.push_back({first, last, length, error.translation().norm() / length,
                                 devkitRotationAngle(error.rotationMatrix()) / length});
    }
  }
  if (result.segments.empty()) {
    throw EvalError(fmt::format(
        "no KITTI segment fits: the ground-truth path is {:.1f} m long over {} frames, the "
        "shortest segment length is {} m",
        result.path_length_m, pairs.size(),
        *std::min_element(options.lengths_m.begin(), options.lengths_m.end())));
  }

  double t_sum = 0.0;
  double r_sum = 0.0;
  for (const KittiSegmentError& s : result.segments) {
    t_sum += s.t_err;
    r_sum += s.r_err_rad_per_m;
  }
  const auto count = static_cast<double>(result.segments.size());
  result.t_rel_percent = 100.0 * t_sum / count;
  result.r_rel_deg_per_100m = kRadPerMToDegPer100m * r_sum / count;

  for (const double length : options.lengths_m) {
    KittiLengthError entry;
    entry.length_m = length;
    double t = 0.0;
    double r = 0.0;
    for (const KittiSegmentError& s : result.segments) {
      if (s.length_m != length) continue;
      ++entry.segments;
      t += s.t_err;
      r += s.r_err_rad_per_m;
    }
    if (entry.segments == 0) continue;
    entry.t_rel_percent = 100.0 * t / static_cast<double>(entry.segments);
    entry.r_rel_deg_per_100m = kRadPerMToDegPer100m * r / static_cast<double>(entry.segments);
    result.per_length.push_back(entry);
  }
  return result;
}

}  // namespace edgeslam
