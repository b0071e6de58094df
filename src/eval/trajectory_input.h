#pragma once
// Loading the two trajectories to compare (TUM or KITTI files, format guessed when not given) and
// pairing their poses the way the formats allow.
#include <filesystem>
#include <string>
#include <vector>

#include "eval/association.h"
#include "io/trajectory.h"

namespace edgeslam {

enum class TrajectoryFormat { kAuto, kTum, kKitti };

std::string toString(TrajectoryFormat format);
// Accepts auto|tum|kitti; throws EvalError otherwise.
TrajectoryFormat parseTrajectoryFormat(const std::string& name);

// From the first data line: 8 numbers -> TUM, 12 -> KITTI. Throws EvalError naming the file and
// the count otherwise (or when the file is missing or has no data line).
TrajectoryFormat guessTrajectoryFormat(const std::filesystem::path& path);

struct LoadedTrajectory {
  std::filesystem::path path;
  TrajectoryFormat format = TrajectoryFormat::kTum;
  bool has_timestamps = true;  // false for KITTI poses without a times file (stamped 0, 1, 2...)
  Trajectory poses;
};

// `times` (may be empty) stamps KITTI poses; it is ignored for TUM files. Throws EvalError when the
// file is missing or empty, DatasetError on malformed lines.
LoadedTrajectory loadTrajectory(const std::filesystem::path& path, TrajectoryFormat format,
                                const std::vector<double>& times = {});

// Two KITTI files of equal length pair by index; otherwise poses are associated by timestamp
// (max_dt in seconds). Throws EvalError when nothing pairs (naming both time ranges) or a KITTI
// file without times must be matched to a time-stamped one.
PosePairs pairTrajectories(const LoadedTrajectory& gt, const LoadedTrajectory& est,
                           double max_dt = kDefaultMaxTimeDifference);

}  // namespace edgeslam
