#pragma once
// Routes for navigation made from a stored map: checkpoints at even spacing along the path the
// camera took while mapping (the paper's robot study), or positions given one by one.
#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "store/map_store.h"

namespace edgeslam {

struct RouteAlongKeyFramesOptions {
  double spacing_m = 0.5;  // between checkpoints along the path
  // Only keyframes made from these frames (inclusive) of the mapping session; all when absent.
  std::optional<std::uint64_t> first_frame;
  std::optional<std::uint64_t> last_frame;
};

// Checkpoints every `spacing_m` of path length along the session's keyframe centres in the order
// they were made, from the first to the last (which is always a checkpoint). Throws
// std::invalid_argument when fewer than two keyframes are in range or the path is shorter than
// one spacing.
RouteRecord routeAlongKeyFrames(const StoredSession& session,
                                const RouteAlongKeyFramesOptions& options);

// The map's up direction as the cameras saw it: the mean of their "up" axes (-y of each camera),
// unit. Falls back to -y of the map when the cameras disagree too much to say (mean below 0.5).
Eigen::Vector3d upOfKeyFrames(const std::vector<KeyFrameRecord>& keyframes);

// Positions "x y z" one per line ('#' comments and blank lines skipped); throws
// std::invalid_argument naming the line on anything else.
std::vector<Eigen::Vector3d> parseCheckpointPositions(const std::string& text);

}  // namespace edgeslam
