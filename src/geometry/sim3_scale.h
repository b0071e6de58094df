#pragma once
// The scale of a similarity between two monocular maps where reprojection cannot see it. When the
// two cameras stand where each other stands (two clients passing one place, one session's frames
// replayed in another), a change of scale about the shared centre moves no projection: a
// refinement by reprojection lets the scale drift (KITTI 03, two clients on overlapping frames:
// 1.00 from RANSAC on the points, 0.62 after refinement, the merged map 45 m off). There the
// points' own ranges give it: each match's distance from the second camera, measured in both maps.
#include <optional>
#include <span>

#include "geometry/sim3.h"
#include "geometry/sim3_solver.h"

namespace edgeslam {

// Distance between the two camera centres over the median range of the matches from camera 1
// (both in camera 1's units); nullopt without matches.
std::optional<double> cameraBaselineOverRange(const Sim3d& cam1_from_cam2,
                                              std::span<const Sim3Match> matches);

// Median over the matches of |point1 - centre2| / |point2|, centre2 being camera 2's centre in
// camera 1 (cam1_from_cam2's translation): the scale that puts each point at the same range from
// camera 2 in both maps. Robust to a minority of wrong matches; nullopt without matches.
std::optional<double> scaleFromRanges(const Sim3d& cam1_from_cam2,
                                      std::span<const Sim3Match> matches);

}  // namespace edgeslam
