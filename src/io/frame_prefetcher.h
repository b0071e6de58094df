#pragma once
// Reads a dataset's frames on a thread of its own, a few frames ahead of the consumer, as a camera
// driver hands over frames that are already decoded: a slow read (a cold file, a stalled disk)
// then delays a frame only when it outlasts the frames already waiting.
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <exception>
#include <thread>

#include "io/dataset.h"
#include "util/mutex.h"

namespace edgeslam {

struct PrefetchedFrame {
  DatasetFrame frame;
  double load_ms = 0.0;  // reading and decoding it, on the prefetching thread
};

struct FramePrefetcherOptions {
  std::size_t frames_ahead = 4;  // at least 1
  // Added to the reading thread's nice value: with frames paced at the camera's rate, decoding
  // then takes the time the consumer leaves idle instead of preempting it.
  int thread_nice = 0;
};

class FramePrefetcher {
 public:
  // Reads frames 0 .. count-1 of `reader`, which only this object's thread calls from now on
  // and which must outlive it. Throws std::invalid_argument for frames_ahead 0.
  FramePrefetcher(DatasetReader& reader, std::size_t count, FramePrefetcherOptions options = {});
  ~FramePrefetcher();
  FramePrefetcher(const FramePrefetcher&) = delete;
  FramePrefetcher& operator=(const FramePrefetcher&) = delete;

  // The next frame in order, waiting for it if needed. Rethrows what reading it threw; throws
  // std::out_of_range past the last frame.
  PrefetchedFrame next();
  // Whether the frame after the last one handed out is read already (a camera has delivered it).
  bool nextIsReady();

 private:
  void run();

  DatasetReader& reader_;
  const std::size_t count_;
  const FramePrefetcherOptions options_;
  Mutex mutex_;
  std::condition_variable changed_;
  std::deque<PrefetchedFrame> ready_ GUARDED_BY(mutex_);
  std::exception_ptr error_ GUARDED_BY(mutex_);  // reading the frame after the ready ones failed
  std::size_t handed_out_ GUARDED_BY(mutex_) = 0;
  bool stopping_ GUARDED_BY(mutex_) = false;
  std::thread thread_;
};

}  // namespace edgeslam
