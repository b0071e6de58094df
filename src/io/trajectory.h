#pragma once
// Trajectories (camera-to-world poses with timestamps) and their TUM / KITTI text formats.
#include <filesystem>
#include <vector>

#include "geometry/se3.h"

namespace edgeslam {

struct StampedPose {
  double timestamp = 0.0;
  SE3d pose;  // camera-to-world
};

using Trajectory = std::vector<StampedPose>;

// TUM: `timestamp tx ty tz qx qy qz qw` per line, '#' comments and blank lines ignored.
// Throws DatasetError naming file and line on malformed input.
Trajectory readTumTrajectory(const std::filesystem::path& path);
void writeTumTrajectory(const std::filesystem::path& path, const Trajectory& trajectory);

// KITTI: 12 numbers per line (3x4 row-major camera-to-world); no timestamps.
std::vector<SE3d> readKittiPoses(const std::filesystem::path& path);
void writeKittiPoses(const std::filesystem::path& path, const std::vector<SE3d>& poses);

// One timestamp per line (KITTI times.txt).
std::vector<double> readTimes(const std::filesystem::path& path);

// KITTI poses paired with times (or with their line index when `times` is empty).
Trajectory kittiToTrajectory(const std::vector<SE3d>& poses, const std::vector<double>& times);

}  // namespace edgeslam
