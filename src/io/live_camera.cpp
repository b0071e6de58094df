#include "io/live_camera.h"

#include <chrono>
#include <thread>
#include <utility>

namespace edgeslam {

LiveCameraClock steadyLiveCameraClock() {
  const auto start = std::chrono::steady_clock::now();
  return {.now_ms =
              [start] {
                return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() -
                                                                 start)
                    .count();
              },
          .sleep_ms =
              [](double ms) {
                if (ms > 0.0) {
                  std::this_thread::sleep_for(std::chrono::duration<double, std::milli>(ms));
                }
              }};
}

LiveCamera::LiveCamera(DatasetReader& reader, std::size_t count, LiveCameraClock clock,
                       LiveCameraOptions options)
    : reader_(reader),
      schedule_(reader.timestamps(), count),
      clock_(std::move(clock)),
      options_(options) {}

std::optional<LiveFrame> LiveCamera::grab() {
  const std::optional<LiveFramePick> pick = schedule_.next(last_taken_, clock_.now_ms());
  if (!pick) return std::nullopt;
  LiveFrame out;
  out.index = pick->index;
  out.due_ms = schedule_.dueMs(pick->index);
  out.skipped = pick->skipped;
  const double start_ms = clock_.now_ms();
  if (options_.extra_load_ms > 0.0) clock_.sleep_ms(options_.extra_load_ms);
  out.frame = reader_.load(pick->index);
  out.load_ms = clock_.now_ms() - start_ms;
  ++read_;
  skipped_ += pick->skipped;
  last_taken_ = pick->index;
  // Read early (the consumer is ahead): handed over at its time, not before. A read that ran
  // past it hands the frame over late; the next grab then skips what came due meanwhile.
  clock_.sleep_ms(out.due_ms - clock_.now_ms());
  return out;
}

}  // namespace edgeslam
