#pragma once
// Hands the latest camera image from the run loop to the viewer, only while a page shows it and
// at most `max_rate_hz` times a second: the run loop asks wanted() (two atomic loads) before it
// copies anything, and the JPEG is drawn and encoded on the viewer's thread, once per image.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "util/mutex.h"
#include "viz/frame_image.h"

namespace edgeslam::viz {

class FrameImageSlot {
 public:
  explicit FrameImageSlot(double max_rate_hz = 5.0,
                          std::chrono::milliseconds page_timeout = std::chrono::seconds(2));

  // Run loop: true when a page asked for an image lately and the last one is old enough.
  bool wanted() const;
  void publish(FrameImage frame);

  // Viewer: the latest image as JPEG (nullopt before the first); marks the image as wanted.
  std::optional<std::string> jpeg();

 private:
  static std::int64_t nowNs();

  std::int64_t min_interval_ns_;
  std::int64_t page_timeout_ns_;
  std::atomic<std::int64_t> last_request_ns_{0};
  std::atomic<std::int64_t> last_publish_ns_{0};

  Mutex mutex_;
  FrameImage frame_ GUARDED_BY(mutex_);
  std::uint64_t frame_version_ GUARDED_BY(mutex_) = 0;
  std::string encoded_ GUARDED_BY(mutex_);
  std::uint64_t encoded_version_ GUARDED_BY(mutex_) = 0;
};

}  // namespace edgeslam::viz
