#include "io/live_frame_schedule.h"

#include <algorithm>
#include <stdexcept>

namespace edgeslam {

LiveFrameSchedule::LiveFrameSchedule(const std::vector<double>& stamps, std::size_t count) {
  if (count > stamps.size()) {
    throw std::invalid_argument("live frame schedule: more frames than timestamps");
  }
  due_ms_.reserve(count);
  for (std::size_t i = 0; i < count; ++i) {
    const double due = (stamps[i] - stamps[0]) * 1000.0;
    // A stamp that is not finite or goes back is due with the frame before it (the frame order
    // guard rejects the frame itself later); the clock never runs backwards.
    due_ms_.push_back(due_ms_.empty() ? 0.0 : std::max(due_ms_.back(), due >= 0.0 ? due : 0.0));
  }
}

std::optional<std::size_t> LiveFrameSchedule::newestDue(double elapsed_ms) const {
  const auto after = std::upper_bound(due_ms_.begin(), due_ms_.end(), elapsed_ms);
  if (after == due_ms_.begin()) return std::nullopt;
  return static_cast<std::size_t>(after - due_ms_.begin()) - 1;
}

std::optional<LiveFramePick> LiveFrameSchedule::next(std::optional<std::size_t> last_taken,
                                                     double elapsed_ms) const {
  const std::size_t first_untaken = last_taken ? *last_taken + 1 : 0;
  if (first_untaken >= due_ms_.size()) return std::nullopt;
  const std::optional<std::size_t> newest = newestDue(elapsed_ms);
  if (!newest || *newest < first_untaken) {
    return LiveFramePick{.index = first_untaken,
                         .skipped = 0,
                         .wait_ms = std::max(0.0, due_ms_[first_untaken] - elapsed_ms)};
  }
  return LiveFramePick{.index = *newest, .skipped = *newest - first_untaken, .wait_ms = 0.0};
}

}  // namespace edgeslam
