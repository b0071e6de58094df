#include "io/live_camera.h"

#include <algorithm>
#include <chrono>
#include <utility>
#include <vector>

namespace edgeslam {
namespace {

constexpr std::size_t kBusyWindow = 5;  // frames the consumer's next busy time is predicted from

}  // namespace

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
      options_(options) {
  if (options_.read_ahead) thread_ = std::thread([this] { readingThread(); });
}

LiveCamera::~LiveCamera() {
  if (!thread_.joinable()) return;
  {
    MutexLock lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

LiveCamera::Read LiveCamera::readHere(std::size_t index) {
  Read read;
  read.index = index;
  const double start_ms = clock_.now_ms();
  try {
    if (options_.extra_load_ms > 0.0) clock_.sleep_ms(options_.extra_load_ms);
    read.frame = reader_.load(index);
  } catch (...) {
    read.error = std::current_exception();
  }
  read.load_ms = clock_.now_ms() - start_ms;
  return read;
}

void LiveCamera::readingThread() {
  for (;;) {
    std::size_t index = 0;
    {
      MutexLock lock(mutex_);
      lock.wait(changed_, [this]() REQUIRES(mutex_) { return stopping_ || to_read_.has_value(); });
      if (stopping_) return;
      index = *to_read_;
    }
    Read read = readHere(index);
    {
      MutexLock lock(mutex_);
      to_read_.reset();
      done_ = std::move(read);
    }
    changed_.notify_all();
  }
}

void LiveCamera::requestRead(std::size_t index) {
  {
    MutexLock lock(mutex_);
    to_read_ = index;
  }
  changed_.notify_all();
  requested_ = index;
  ++reads_;
}

LiveCamera::Read LiveCamera::waitForRead() {
  MutexLock lock(mutex_);
  lock.wait(changed_, [this]() REQUIRES(mutex_) { return done_.has_value(); });
  Read read = std::move(*done_);
  done_.reset();
  requested_.reset();
  return read;
}

double LiveCamera::busyEstimateMs() const {
  if (busy_ms_.empty()) return 0.0;
  std::vector<double> sorted(busy_ms_.begin(), busy_ms_.end());
  std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
  return sorted[sorted.size() / 2];
}

std::optional<LiveFrame> LiveCamera::grab() {
  const double now_ms = clock_.now_ms();
  if (handed_over_ms_) {
    busy_ms_.push_back(now_ms - *handed_over_ms_);
    if (busy_ms_.size() > kBusyWindow) busy_ms_.pop_front();
  }
  const std::optional<LiveFramePick> pick = schedule_.next(last_taken_, now_ms);
  if (!pick) return std::nullopt;
  std::optional<Read> read;
  if (requested_) {
    // The frame read ahead: still the newest due (or not due yet), or less than one read behind
    // the newest, so that taking it is sooner than reading the newest.
    const bool stale = *requested_ < pick->index &&
                       schedule_.dueMs(pick->index) - schedule_.dueMs(*requested_) > last_load_ms_;
    read = waitForRead();
    if (stale) {
      ++unused_reads_;
      read.reset();
    }
  }
  if (!read) {
    if (options_.read_ahead) {
      requestRead(pick->index);
      read = waitForRead();
    } else {
      read = readHere(pick->index);
      ++reads_;
    }
  }
  if (read->error) std::rethrow_exception(read->error);
  last_load_ms_ = read->load_ms;
  LiveFrame out;
  out.index = read->index;
  out.due_ms = schedule_.dueMs(read->index);
  out.load_ms = read->load_ms;
  out.skipped = read->index - (last_taken_ ? *last_taken_ + 1 : 0);
  out.frame = std::move(read->frame);
  skipped_ += out.skipped;
  last_taken_ = out.index;
  if (options_.read_ahead && out.index + 1 < schedule_.count()) {
    // The newest frame due when the consumer is expected back and the read done (they overlap),
    // the next one at the earliest.
    const double back_ms =
        std::max(clock_.now_ms(), out.due_ms) + std::max(busyEstimateMs(), last_load_ms_);
    const std::size_t predicted =
        std::max(out.index + 1, schedule_.newestDue(back_ms).value_or(out.index + 1));
    requestRead(std::min(predicted, schedule_.count() - 1));
  }
  // Read early (the consumer is ahead): handed over at its time, not before. A read that ran
  // past it hands the frame over late; the next grab then skips what came due meanwhile.
  clock_.sleep_ms(out.due_ms - clock_.now_ms());
  handed_over_ms_ = clock_.now_ms();
  return out;
}

}  // namespace edgeslam
