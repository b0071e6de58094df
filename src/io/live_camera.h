#pragma once
// A dataset played as a live camera (`--realtime`): each frame is handed over at its due time
// on the camera clock, and a consumer that comes back late gets the newest frame already due;
// the frames it was too busy for are skipped and never read.
//
// Reading (the dataset's decoding, which a real camera does not charge to the client) is kept
// off the latency where it can be: while the consumer works on a frame, a reading thread reads
// the frame predicted to be the newest due when the consumer comes back (from how long the last
// frames took). A prediction that turns out stale is still taken when that is sooner than
// reading the newest frame (its due time is less than one read behind); otherwise the newest
// frame is read and the predicted one was read in vain (`unusedReads`).
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <functional>
#include <optional>
#include <thread>

#include "io/dataset.h"
#include "io/live_frame_schedule.h"
#include "util/mutex.h"

namespace edgeslam {

struct LiveCameraClock {
  std::function<double()> now_ms;           // ms since the camera started (frame 0 is due at 0)
  std::function<void(double ms)> sleep_ms;  // waits that long (nothing for ms <= 0)
};

// The steady clock, started now.
LiveCameraClock steadyLiveCameraClock();

struct LiveCameraOptions {
  // Read the predicted next frame on a thread of its own while the consumer works; off, each
  // frame is read on the consumer's thread when it is taken.
  bool read_ahead = true;
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
  // Plays frames 0 .. count-1 of `reader`, which only this object calls from now on and which
  // must outlive it.
  LiveCamera(DatasetReader& reader, std::size_t count, LiveCameraClock clock,
             LiveCameraOptions options = {});
  ~LiveCamera();
  LiveCamera(const LiveCamera&) = delete;
  LiveCamera& operator=(const LiveCamera&) = delete;

  // The next frame, once it is due; nullopt after the last frame. Rethrows what reading threw.
  std::optional<LiveFrame> grab();
  // Frames skipped so far (due while the consumer was busy, never handed over).
  std::size_t skipped() const { return skipped_; }
  // Frames read so far, and those of them read ahead in vain (a newer frame was taken instead).
  std::size_t reads() const { return reads_; }
  std::size_t unusedReads() const { return unused_reads_; }
  const LiveFrameSchedule& schedule() const { return schedule_; }

 private:
  struct Read {
    std::size_t index = 0;
    DatasetFrame frame;
    double load_ms = 0.0;
    std::exception_ptr error;
  };

  Read readHere(std::size_t index);
  void readingThread();
  void requestRead(std::size_t index);
  Read waitForRead();
  double busyEstimateMs() const;

  DatasetReader& reader_;
  const LiveFrameSchedule schedule_;
  const LiveCameraClock clock_;
  const LiveCameraOptions options_;
  // The consumer's side.
  std::optional<std::size_t> last_taken_;
  std::optional<std::size_t> requested_;  // read ahead, not yet collected
  std::optional<double> handed_over_ms_;  // when the last frame was handed over
  std::deque<double> busy_ms_;            // the consumer's last few frames
  double last_load_ms_ = 0.0;
  std::size_t skipped_ = 0;
  std::size_t reads_ = 0;
  std::size_t unused_reads_ = 0;
  // Shared with the reading thread.
  Mutex mutex_;
  std::condition_variable changed_;
  std::optional<std::size_t> to_read_ GUARDED_BY(mutex_);
  std::optional<Read> done_ GUARDED_BY(mutex_);
  bool stopping_ GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

}  // namespace edgeslam
