#include "viz/trajectory_decimator.h"

#include <algorithm>

namespace edgeslam::viz {

TrajectoryDecimator::TrajectoryDecimator(std::size_t capacity)
    : capacity_(std::max<std::size_t>(capacity, 2)) {
  positions_.reserve(capacity_);
}

void TrajectoryDecimator::add(const Eigen::Vector3d& position) {
  if (offered_++ % stride_ != 0) return;
  if (positions_.size() == capacity_) {
    // Keep the even entries: they are the ones a doubled stride would have kept from the start.
    std::size_t kept = 0;
    for (std::size_t i = 0; i < positions_.size(); i += 2) positions_[kept++] = positions_[i];
    positions_.resize(kept);
    stride_ *= 2;
    if ((offered_ - 1) % stride_ != 0) return;
  }
  positions_.push_back(position);
}

}  // namespace edgeslam::viz
