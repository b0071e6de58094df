#include "io/frame_prefetcher.h"

#include <chrono>
#include <stdexcept>
#include <utility>

#include "util/thread_priority.h"

namespace edgeslam {

FramePrefetcher::FramePrefetcher(DatasetReader& reader, std::size_t count,
                                 FramePrefetcherOptions options)
    : reader_(reader), count_(count), options_(options) {
  if (options_.frames_ahead == 0) {
    throw std::invalid_argument("frame prefetcher: frames_ahead must be at least 1");
  }
  thread_ = std::thread([this] { run(); });
}

FramePrefetcher::~FramePrefetcher() {
  {
    MutexLock lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  thread_.join();
}

void FramePrefetcher::run() {
  lowerCurrentThreadPriority(options_.thread_nice);
  for (std::size_t index = 0; index < count_; ++index) {
    {
      MutexLock lock(mutex_);
      lock.wait(changed_, [this]() REQUIRES(mutex_) {
        return stopping_ || ready_.size() < options_.frames_ahead;
      });
      if (stopping_) return;
    }
    PrefetchedFrame prefetched;
    const auto start = std::chrono::steady_clock::now();
    try {
      prefetched.frame = reader_.load(index);
    } catch (...) {
      MutexLock lock(mutex_);
      error_ = std::current_exception();
      changed_.notify_all();
      return;
    }
    prefetched.load_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    {
      MutexLock lock(mutex_);
      ready_.push_back(std::move(prefetched));
    }
    changed_.notify_all();
  }
}

PrefetchedFrame FramePrefetcher::next() {
  MutexLock lock(mutex_);
  if (handed_out_ >= count_) {
    throw std::out_of_range("frame prefetcher: all frames were handed out");
  }
  lock.wait(changed_, [this]() REQUIRES(mutex_) { return !ready_.empty() || error_ != nullptr; });
  if (ready_.empty()) std::rethrow_exception(error_);
  PrefetchedFrame out = std::move(ready_.front());
  ready_.pop_front();
  ++handed_out_;
  lock.unlock();
  changed_.notify_all();
  return out;
}

bool FramePrefetcher::nextIsReady() {
  MutexLock lock(mutex_);
  return !ready_.empty();
}

}  // namespace edgeslam
