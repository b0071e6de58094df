#include "linkem/link_pipe.h"

#include <sys/socket.h>

#include <algorithm>
#include <cerrno>
#include <vector>

#include "linkem/socket.h"

namespace edgeslam {
namespace {

// The reader stops taking bytes while the bottleneck is this far behind: the rest waits in the
// sender's socket buffers, so the sender feels back-pressure as it would on a slow link.
constexpr auto kMaxBacklog = std::chrono::milliseconds(50);
// Bytes the bottleneck sends in this time make one read, so rate changes apply promptly.
constexpr double kReadWindowS = 0.02;
constexpr std::size_t kMaxRead = 64 * 1024;
constexpr std::size_t kMaxWrite = 256 * 1024;

}  // namespace

LinkPipe::LinkPipe(int from, int to, ParamsSource params, LinkPipeCounters counters,
                   std::uint64_t seed, std::size_t max_queue_bytes,
                   std::function<void()> on_failure)
    : from_(from),
      to_(to),
      params_(std::move(params)),
      counters_(counters),
      model_(seed),
      max_queue_bytes_(std::max<std::size_t>(max_queue_bytes, kMaxRead)),
      on_failure_(std::move(on_failure)) {}

LinkPipe::~LinkPipe() {
  requestStop();
  join();
}

void LinkPipe::start() {
  running_threads_ = 2;
  reader_ = std::thread([this] {
    readLoop();
    --running_threads_;
  });
  writer_ = std::thread([this] {
    writeLoop();
    --running_threads_;
  });
}

void LinkPipe::requestStop() {
  {
    MutexLock lock(mutex_);
    stop_ = true;
  }
  data_ready_.notify_all();
  space_ready_.notify_all();
}

void LinkPipe::join() {
  if (reader_.joinable()) reader_.join();
  if (writer_.joinable()) writer_.join();
}

std::size_t LinkPipe::readSize(const LinkDirectionParams& params) const {
  if (params.mbps <= 0.0) return kMaxRead;
  const double window_bytes = params.mbps * 1e6 / 8.0 * kReadWindowS;
  return std::clamp(static_cast<std::size_t>(window_bytes), LinkDirectionModel::kSegmentBytes,
                    kMaxRead);
}

void LinkPipe::readLoop() {
  std::vector<char> buffer(kMaxRead);
  while (true) {
    {
      MutexLock lock(mutex_);
      lock.wait(space_ready_,
                [&]() REQUIRES(mutex_) { return stop_ || queued_bytes_ < max_queue_bytes_; });
      lock.waitUntil(space_ready_, model_.linkFreeAt() - kMaxBacklog,
                     [&]() REQUIRES(mutex_) { return stop_; });
      if (stop_) return;
    }
    const std::size_t wanted = readSize(params_());
    const ssize_t got = ::recv(from_, buffer.data(), wanted, 0);
    if (got < 0 && errno == EINTR) continue;
    const auto now = LinkClock::now();
    {
      MutexLock lock(mutex_);
      if (stop_) return;
    }
    if (got < 0) {
      on_failure_();
      return;
    }
    if (got == 0) {
      MutexLock lock(mutex_);
      queue_.push_back({std::max(now, model_.lastDelivery()), {}, true});
      data_ready_.notify_all();
      return;
    }
    const auto segments = model_.schedule(static_cast<std::size_t>(got), now, params_());
    MutexLock lock(mutex_);
    std::size_t offset = 0;
    for (const ScheduledSegment& segment : segments) {
      queue_.push_back({segment.deliver_at, std::string(buffer.data() + offset, segment.bytes)});
      offset += segment.bytes;
      if (segment.lost && counters_.lost_segments != nullptr) ++*counters_.lost_segments;
    }
    queued_bytes_ += static_cast<std::size_t>(got);
    data_ready_.notify_all();
  }
}

void LinkPipe::writeLoop() {
  MutexLock lock(mutex_);
  std::string out;
  while (!stop_) {
    if (queue_.empty()) {
      lock.wait(data_ready_);
      continue;
    }
    const auto now = LinkClock::now();
    if (now < queue_.front().deliver_at) {
      lock.waitUntil(data_ready_, queue_.front().deliver_at);
      continue;
    }
    out.clear();
    bool end_of_stream = false;
    while (!queue_.empty() && queue_.front().deliver_at <= now && out.size() < kMaxWrite) {
      if (queue_.front().end_of_stream) {
        end_of_stream = true;
        queue_.pop_front();
        break;
      }
      out += queue_.front().data;
      queued_bytes_ -= queue_.front().data.size();
      queue_.pop_front();
    }
    space_ready_.notify_all();
    lock.unlock();
    if (!out.empty()) {
      // Counted before the send so that a reader who has the bytes also sees them counted.
      if (counters_.delivered_bytes != nullptr) *counters_.delivered_bytes += out.size();
      if (!sendAll(to_, out.data(), out.size())) {
        on_failure_();
        return;
      }
    }
    if (end_of_stream) {
      ::shutdown(to_, SHUT_WR);
      return;
    }
    lock.lock();
  }
}

}  // namespace edgeslam
