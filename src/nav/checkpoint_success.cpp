#include "nav/checkpoint_success.h"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace edgeslam {

CheckpointSuccess checkpointSuccess(const std::vector<Eigen::Vector3d>& checkpoints,
                                    const std::vector<AnnouncedCheckpoint>& announced,
                                    const std::vector<Eigen::Vector3d>& true_positions,
                                    double radius_m) {
  CheckpointSuccess out;
  out.checkpoints = checkpoints.size();
  for (const Eigen::Vector3d& checkpoint : checkpoints) {
    double closest = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3d& p : true_positions) {
      closest = std::min(closest, (p - checkpoint).norm());
    }
    out.closest_m.push_back(closest);
    if (closest <= radius_m) ++out.passed;
  }
  std::vector<bool> reached(checkpoints.size(), false);
  for (const AnnouncedCheckpoint& a : announced) {
    if (a.checkpoint >= checkpoints.size()) {
      throw std::invalid_argument("an announced checkpoint the route does not have");
    }
    const double error = (a.true_position - checkpoints[a.checkpoint]).norm();
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
