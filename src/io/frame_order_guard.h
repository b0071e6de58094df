#pragma once
// Frames must reach tracking in time order: a frame whose timestamp repeats the last one (a
// duplicated frame) or goes back (out of order, a stale frame, a clock stepped back) would feed
// the motion model a negative or zero time step and the trajectory a pose out of place. Such a
// frame is skipped and counted, as a camera driver drops a stale frame.
#include <cstddef>
#include <optional>

namespace edgeslam {

enum class FrameOrderRejection { kDuplicateTimestamp, kTimestampBackwards, kNotFinite };
const char* toString(FrameOrderRejection rejection);  // snake_case, the metrics.json key

class FrameOrderGuard {
 public:
  // nullopt: the frame is newer than every frame accepted so far and is accepted.
  std::optional<FrameOrderRejection> check(double timestamp);

  std::size_t duplicates() const { return duplicates_; }
  std::size_t backwards() const { return backwards_; }
  std::size_t notFinite() const { return not_finite_; }
  std::size_t rejected() const { return duplicates_ + backwards_ + not_finite_; }

 private:
  std::optional<double> newest_;
  std::size_t duplicates_ = 0;
  std::size_t backwards_ = 0;
  std::size_t not_finite_ = 0;
};

}  // namespace edgeslam
