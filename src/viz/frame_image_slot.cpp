#include "viz/frame_image_slot.h"

#include <utility>

namespace edgeslam::viz {

FrameImageSlot::FrameImageSlot(double max_rate_hz, std::chrono::milliseconds page_timeout)
    : min_interval_ns_(static_cast<std::int64_t>(1e9 / max_rate_hz)),
      page_timeout_ns_(std::chrono::duration_cast<std::chrono::nanoseconds>(page_timeout).count()) {
}

std::int64_t FrameImageSlot::nowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

bool FrameImageSlot::wanted() const {
  const std::int64_t requested = last_request_ns_.load(std::memory_order_relaxed);
  if (requested == 0) return false;
  const std::int64_t now = nowNs();
  return now - requested < page_timeout_ns_ &&
         now - last_publish_ns_.load(std::memory_order_relaxed) >= min_interval_ns_;
}

void FrameImageSlot::publish(FrameImage frame) {
  last_publish_ns_ = nowNs();
  MutexLock lock(mutex_);
  frame_ = std::move(frame);
  ++frame_version_;
}

std::optional<std::string> FrameImageSlot::jpeg() {
  last_request_ns_ = nowNs();
  MutexLock lock(mutex_);
  if (frame_version_ == 0) return std::nullopt;
  if (encoded_version_ != frame_version_) {
    encoded_ = renderFrameJpeg(frame_);
    encoded_version_ = frame_version_;
  }
  return encoded_;
}

}  // namespace edgeslam::viz
