#pragma once
// The camera clock of a dataset played at its own rate (`--realtime`): frame i is due
// (stamp[i] - stamp[0]) after the start, whether or not the client has finished the one before.
// A live camera does not wait, so a client that comes back late takes the newest frame already
// due and the ones it slept through are gone (skipped, never decoded).
#include <cstddef>
#include <optional>
#include <vector>

namespace edgeslam {

struct LiveFramePick {
  std::size_t index = 0;    // the frame to take next
  std::size_t skipped = 0;  // frames between the last one taken and `index`, due and passed over
  double wait_ms = 0.0;     // how long until `index` is due (0 when it is due already)
};

class LiveFrameSchedule {
 public:
  // The first `count` of `stamps` (seconds, non-decreasing in a well-formed dataset; a stamp
  // that goes back is due as early as the one before it).
  LiveFrameSchedule(const std::vector<double>& stamps, std::size_t count);

  std::size_t count() const { return due_ms_.size(); }
  // When frame i is due, in ms after the start of the clock.
  double dueMs(std::size_t index) const { return due_ms_.at(index); }
  // The newest frame due at `elapsed_ms`, nullopt before the first one.
  std::optional<std::size_t> newestDue(double elapsed_ms) const;
  // The frame to take after `last_taken` (nullopt: none taken yet) at `elapsed_ms`: the newest
  // one due, or, when none newer is due, the next one and the wait for it. nullopt once the
  // last frame has been taken.
  std::optional<LiveFramePick> next(std::optional<std::size_t> last_taken, double elapsed_ms) const;

 private:
  std::vector<double> due_ms_;  // non-decreasing
};

}  // namespace edgeslam
