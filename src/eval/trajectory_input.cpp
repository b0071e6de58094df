#include "eval/trajectory_input.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "eval/eval_error.h"

namespace edgeslam {
namespace {

void requireFile(const std::filesystem::path& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw EvalError(fmt::format("trajectory file not found: {}", path.string()));
  }
}

std::string timeRange(const LoadedTrajectory& t) {
  if (t.poses.empty()) return "no poses";
  const auto [lo, hi] = std::minmax_element(
      t.poses.begin(), t.poses.end(),
      [](const StampedPose& a, const StampedPose& b) { return a.timestamp < b.timestamp; });
  return fmt::format("{} poses, t = {:.6f} .. {:.6f} s", t.poses.size(), lo->timestamp,
                     hi->timestamp);
}

}  // namespace

std::string toString(TrajectoryFormat format) {
  switch (format) {
    case TrajectoryFormat::kAuto:
      return "auto";
    case TrajectoryFormat::kTum:
      return "tum";
    case TrajectoryFormat::kKitti:
      return "kitti";
  }
  return "unknown";
}

TrajectoryFormat parseTrajectoryFormat(const std::string& name) {
  if (name == "auto") return TrajectoryFormat::kAuto;
  if (name == "tum") return TrajectoryFormat::kTum;
  if (name == "kitti") return TrajectoryFormat::kKitti;
  throw EvalError(
      fmt::format("unknown trajectory format '{}' (expected auto, tum or kitti)", name));
}

TrajectoryFormat guessTrajectoryFormat(const std::filesystem::path& path) {
  requireFile(path);
  std::ifstream in(path);
  if (!in) throw EvalError(fmt::format("cannot open {}", path.string()));
  std::string line;
  while (std::getline(in, line)) {
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream tokens(line);
    std::size_t count = 0;
    for (std::string token; tokens >> token;) ++count;
    if (count == 8) return TrajectoryFormat::kTum;
    if (count == 12) return TrajectoryFormat::kKitti;
    throw EvalError(fmt::format(
        "cannot tell the format of {}: its first data line has {} values (TUM has 8, KITTI 12); "
        "pass --format",
        path.string(), count));
  }
  throw EvalError(fmt::format("trajectory file has no poses: {}", path.string()));
}

LoadedTrajectory loadTrajectory(const std::filesystem::path& path, TrajectoryFormat format,
                                const std::vector<double>& times) {
  requireFile(path);
  LoadedTrajectory loaded;
  loaded.path = path;
  loaded.format = format == TrajectoryFormat::kAuto ? guessTrajectoryFormat(path) : format;
  if (loaded.format == TrajectoryFormat::kTum) {
    loaded.poses = readTumTrajectory(path);
  } else {
    const std::vector<SE3d> poses = readKittiPoses(path);
    if (!times.empty() && times.size() != poses.size()) {
      throw EvalError(fmt::format("{} has {} poses but the times file has {} timestamps",
                                  path.string(), poses.size(), times.size()));
    }
    loaded.poses = kittiToTrajectory(poses, times);
    loaded.has_timestamps = !times.empty();
  }
  if (loaded.poses.empty()) {
    throw EvalError(fmt::format("trajectory file has no poses: {}", path.string()));
  }
  return loaded;
}

PosePairs pairTrajectories(const LoadedTrajectory& gt, const LoadedTrajectory& est, double max_dt) {
  const bool both_kitti =
      gt.format == TrajectoryFormat::kKitti && est.format == TrajectoryFormat::kKitti;
  if (both_kitti &&
      (gt.poses.size() == est.poses.size() || !gt.has_timestamps || !est.has_timestamps)) {
    return associateByIndex(gt.poses, est.poses);
  }
  if (!gt.has_timestamps || !est.has_timestamps) {
    throw EvalError(fmt::format(
        "{} is a KITTI file without timestamps and cannot be matched by time to {}: pass --times",
        (gt.has_timestamps ? est.path : gt.path).string(),
        (gt.has_timestamps ? gt.path : est.path).string()));
  }
  PosePairs pairs = associateByTimestamp(gt.poses, est.poses, max_dt);
  if (pairs.empty()) {
    throw EvalError(
        fmt::format("no poses associated within {} s: ground truth {} has {}; estimate {} has {}",
                    max_dt, gt.path.string(), timeRange(gt), est.path.string(), timeRange(est)));
  }
  return pairs;
}

}  // namespace edgeslam
