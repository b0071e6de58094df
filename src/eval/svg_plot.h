#pragma once
// Top-view SVG picture of a ground-truth trajectory and an aligned estimate coloured by its error,
// with grid, scale bar, colour bar, start/end markers and a title.
#include <Eigen/Core>
#include <filesystem>
#include <string>
#include <vector>

namespace edgeslam {

// kAuto: the two axes along which the ground truth extends most; kXZ: the KITTI ground plane (x to
// the right, z forward drawn upwards).
enum class PlotPlane { kAuto, kXZ };

struct TrajectoryPlot {
  std::string title;
  std::string subtitle;
  std::vector<Eigen::Vector3d> ground_truth;
  std::vector<Eigen::Vector3d> estimate;  // already in the ground-truth frame
  std::vector<double> errors;             // one per estimate position, metres
  std::string error_label = "error [m]";
  PlotPlane plane = PlotPlane::kAuto;
};

// Throws EvalError when there is nothing to draw or errors and estimate differ in size.
std::string renderTrajectorySvg(const TrajectoryPlot& plot);
// Writes renderTrajectorySvg to `path`; throws EvalError naming the file when it cannot.
void writeTrajectorySvg(const std::filesystem::path& path, const TrajectoryPlot& plot);

}  // namespace edgeslam
