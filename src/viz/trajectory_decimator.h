#pragma once
// Keeps a growing path bounded: once `capacity` points are held, every other one is dropped and
// from then on only every 2nd (4th, 8th, ...) point offered is kept, so a long run still shows its
// whole path at an even spacing. Adding is O(1) amortised.
#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace edgeslam::viz {

class TrajectoryDecimator {
 public:
  explicit TrajectoryDecimator(std::size_t capacity);

  void add(const Eigen::Vector3d& position);
  const std::vector<Eigen::Vector3d>& positions() const { return positions_; }
  // Points offered per point kept.
  std::size_t stride() const { return stride_; }

 private:
  std::size_t capacity_;
  std::size_t stride_ = 1;
  std::size_t offered_ = 0;
  std::vector<Eigen::Vector3d> positions_;
};

}  // namespace edgeslam::viz
