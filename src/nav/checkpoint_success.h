#pragma once
// How a route was followed, judged by the truth (paper Sec. VI: a checkpoint is reached when the
// true position is within 0.5 m of it). In a replay the true path is the recording's whatever the
// instructions say, so what is judged is the guidance: a checkpoint succeeds when the navigator
// announced it reached (from the estimated pose) while the true path, from the frame before to
// the frame of the announcement, passed within the radius. Paths are straight between frames.
#include <Eigen/Core>
#include <cstddef>
#include <optional>
#include <vector>

namespace edgeslam {

// The navigator said "checkpoint k reached" while the camera truly was at `true_position`,
// having come from `true_from` (the frame before; none for the first frame).
struct AnnouncedCheckpoint {
  std::size_t checkpoint = 0;
  Eigen::Vector3d true_position = Eigen::Vector3d::Zero();
  std::optional<Eigen::Vector3d> true_from;
};

struct CheckpointSuccess {
  std::size_t checkpoints = 0;
  std::size_t reached = 0;  // announced as the true path passed within the radius
  double rate = 0.0;        // reached / checkpoints
  std::size_t passed = 0;   // the true path came within the radius (announced or not)
  // Per announcement: how close the true path since the frame before came to it, metres.
  std::vector<double> announced_error_m;
  // Per checkpoint: the least distance of the true path to it, metres.
  std::vector<double> closest_m;
};

// Everything in one frame (the truth's). Throws std::invalid_argument for an announcement of a
// checkpoint the route does not have.
CheckpointSuccess checkpointSuccess(const std::vector<Eigen::Vector3d>& checkpoints,
                                    const std::vector<AnnouncedCheckpoint>& announced,
                                    const std::vector<Eigen::Vector3d>& true_positions,
                                    double radius_m);

}  // namespace edgeslam
