#pragma once
// A dataset played as a live camera (`--realtime`): each frame is handed over at its due time
// on the camera clock, and a consumer that comes back late gets the newest frame already due;
// the frames it was too busy for are skipped and never read. A frame is decoded only when it is
// the one to hand over next: while the consumer is ahead, in the wait before its due time (as
// a camera exposes it); once the consumer is behind, on demand, so decoding counts in that
// frame's latency.
#include <cstddef>
#include <functional>
#include <optional>

#include "io/dataset.h"
#include "io/live_frame_schedule.h"

namespace edgeslam {

struct LiveCameraClock {
  std::function<double()> now_ms;           // ms since the camera started (frame 0 is due at 0)
  std::function<void(double ms)> sleep_ms;  // waits that long
};

// The steady clock, started now.
LiveCameraClock steadyLiveCameraClock();

struct LiveCameraOptions {
  // Test hook: each read also sleeps this long, a reader (or device) too slow for the camera.
  double extra_load_ms = 0.0;
};

struct LiveFrame {
  DatasetFrame frame;
  std::size_t index = 0;
  double due_ms = 0.0;      // on the camera clock
  double load_ms = 0.0;     // reading and decoding it
  std::size_t skipped = 0;  // frames passed over just before this one
};

class LiveCamera {
 public:
  // Plays frames 0 .. count-1 of `reader`, which must outlive this object.
  LiveCamera(DatasetReader& reader, std::size_t count, LiveCameraClock clock,
             LiveCameraOptions options = {});

  // The next frame, once it is due; nullopt after the last frame. Rethrows what reading threw.
  std::optional<LiveFrame> grab();
  // Frames skipped so far (due while the consumer was busy, never read).
  std::size_t skipped() const { return skipped_; }
  // Frames read so far.
  std::size_t read() const { return read_; }
  const LiveFrameSchedule& schedule() const { return schedule_; }

 private:
  DatasetReader& reader_;
  const LiveFrameSchedule schedule_;
  const LiveCameraClock clock_;
  const LiveCameraOptions options_;
  std::optional<std::size_t> last_taken_;
  std::size_t skipped_ = 0;
  std::size_t read_ = 0;
};

}  // namespace edgeslam
