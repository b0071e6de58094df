#pragma once
// Which tracked frames have their poses in the frame of the map a run began with. A map started
// after tracking was lost for good (Tracker::startNewMap) has a frame of its own until a merge
// moves it onto the first map's part; from then on its frames are in the first map's frame. The
// run's trajectory files hold only poses in that frame (one alignment fits them); the others go
// to a file per map.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

class FirstMapFrame {
 public:
  // After each frame (the tracking thread): frames recorded so far, and the map tracking is in
  // (0: the first; k: the k-th started after a loss).
  void noteProgress(std::size_t frames_recorded, std::size_t current_map);
  // The map tracking is in was merged onto the first map's part (any thread). Its frames from
  // the next one not yet recorded on are in the first map's frame (the frame being tracked may
  // have used poses from before the move).
  void currentMapJoinedFirst();

  // The pose recorded for frame record `index`, tracked in map `map`, was in the first map's
  // frame when it was estimated.
  bool inFirstAtFrameTime(std::size_t index, std::uint32_t map) const;
  // The final pose of a frame tracked in map `map` is in the first map's frame.
  bool inFirstFinally(std::uint32_t map) const;

 private:
  std::atomic<std::size_t> frames_recorded_{0};
  std::atomic<std::size_t> current_map_{0};
  mutable Mutex mutex_;
  // By map (index k - 1): the first frame record in the first map's frame.
  std::vector<std::optional<std::size_t>> joined_from_ GUARDED_BY(mutex_);
};

}  // namespace edgeslam
