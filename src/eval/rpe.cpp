#include "eval/rpe.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "eval/eval_error.h"
#include "geometry/so3.h"

namespace edgeslam {
namespace {

// Coordinate along which pose j is "delta later" than pose i: time or path length.
std::vector<double> progressCoordinate(const PosePairs& pairs, DeltaUnit unit) {
  std::vector<double> s(pairs.size(), 0.0);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    if (unit == DeltaUnit::kSeconds) {
      s[i] = pairs[i].gt_timestamp;
    } else if (i > 0) {
      s[i] = s[i - 1] + (pairs[i].gt.translation() - pairs[i - 1].gt.translation()).norm();
    }
  }
  return s;
}

std::vector<std::pair<std::size_t, std::size_t>> selectPosePairs(const PosePairs& pairs,
                                                                 const RpeOptions& options) {
  std::vector<std::pair<std::size_t, std::size_t>> selected;
  if (options.unit == DeltaUnit::kFrames) {
    const auto step = static_cast<std::size_t>(options.delta);
    for (std::size_t i = 0; i + step < pairs.size(); ++i) selected.emplace_back(i, i + step);
    return selected;
  }
  const std::vector<double> s = progressCoordinate(pairs, options.unit);
  for (std::size_t i = 0; i < pairs.size(); ++i) {
    // Tolerate rounding so that e.g. 0.1 s steps add up to a 1.0 s delta.
    const double target = s[i] + options.delta - 1e-9 * std::max(1.0, std::abs(options.delta));
    const auto it =
        std::lower_bound(s.begin() + static_cast<std::ptrdiff_t>(i) + 1, s.end(), target);
    if (it == s.end()) break;  // s is non-decreasing, so no later i finds a partner either
    selected.emplace_back(i, static_cast<std::size_t>(it - s.begin()));
  }
  return selected;
}

}  // namespace

std::string toString(DeltaUnit unit) {
  switch (unit) {
    case DeltaUnit::kFrames:
      return "frames";
    case DeltaUnit::kSeconds:
      return "seconds";
    case DeltaUnit::kMetres:
      return "metres";
  }
  return "unknown";
}

DeltaUnit parseDeltaUnit(const std::string& name) {
  if (name == "frames" || name == "f") return DeltaUnit::kFrames;
  if (name == "seconds" || name == "s") return DeltaUnit::kSeconds;
  if (name == "metres" || name == "meters" || name == "m") return DeltaUnit::kMetres;
  throw EvalError(
      fmt::format("unknown delta unit '{}' (expected frames, seconds or metres)", name));
}

RpeResult computeRpe(const PosePairs& pairs, const RpeOptions& options) {
  if (!(options.delta > 0.0) || !std::isfinite(options.delta)) {
    throw EvalError(fmt::format("RPE delta must be positive, got {}", options.delta));
  }
  if (options.unit == DeltaUnit::kFrames && options.delta != std::floor(options.delta)) {
    throw EvalError(
        fmt::format("RPE delta in frames must be a whole number, got {}", options.delta));
  }
  RpeResult result;
  result.options = options;
  if (options.align == AlignMode::kSim3) result.scale = alignPairs(pairs, AlignMode::kSim3).scale();

  for (const auto& [i, j] : selectPosePairs(pairs, options)) {
    const SE3d gt_motion = pairs[i].gt.inverse() * pairs[j].gt;
    SE3d est_motion = pairs[i].est.inverse() * pairs[j].est;
    est_motion.setTranslation(result.scale * est_motion.translation());
    const SE3d error = gt_motion.inverse() * est_motion;
    const double angle = so3Log(error.rotation()).norm();
    result.errors.push_back({i, j, error.translation().norm(), angle * 180.0 / std::numbers::pi});
  }
  if (result.errors.empty()) {
    throw EvalError(fmt::format("no pose pairs are {} {} apart ({} poses)", options.delta,
                                toString(options.unit), pairs.size()));
  }
  std::vector<double> translation;
  std::vector<double> rotation;
  for (const RelativeError& e : result.errors) {
    translation.push_back(e.translation_m);
    rotation.push_back(e.rotation_deg);
  }
  result.translation = computeStatistics(std::move(translation));
  result.rotation = computeStatistics(std::move(rotation));
  return result;
}

}  // namespace edgeslam
