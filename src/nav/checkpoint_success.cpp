#include "nav/checkpoint_success.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "nav/path_distance.h"

namespace edgeslam {

CheckpointSuccess checkpointSuccess(const std::vector<Eigen::Vector3d>& checkpoints,
                                    const std::vector<AnnouncedCheckpoint>& announced,
                                    const std::vector<Eigen::Vector3d>& true_positions,
                                    double radius_m) {
  CheckpointSuccess out;
  out.checkpoints = checkpoints.size();
  for (const Eigen::Vector3d& checkpoint : checkpoints) {
    double closest = std::numeric_limits<double>::infinity();
    for (std::size_t i = 0; i < true_positions.size(); ++i) {
      const Eigen::Vector3d& from = true_positions[i == 0 ? 0 : i - 1];
      closest = std::min(closest, distanceToSegment(checkpoint, from, true_positions[i]));
    }
    out.closest_m.push_back(closest);
    if (closest <= radius_m) ++out.passed;
  }
  std::vector<bool> reached(checkpoints.size(), false);
  for (const AnnouncedCheckpoint& a : announced) {
    if (a.checkpoint >= checkpoints.size()) {
      throw std::invalid_argument("an announced checkpoint the route does not have");
    }
    const double error = distanceToSegment(checkpoints[a.checkpoint],
                                           a.true_from.value_or(a.true_position), a.true_position);
    out.announced_error_m.push_back(error);
    if (error <= radius_m) reached[a.checkpoint] = true;
  }
  out.reached = static_cast<std::size_t>(std::count(reached.begin(), reached.end(), true));
  out.rate = checkpoints.empty()
                 ? 0.0
                 : static_cast<double>(out.reached) / static_cast<double>(checkpoints.size());
  return out;
}

}  // namespace edgeslam
