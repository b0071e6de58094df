#pragma once
// One session's outgoing map slices, encoded once and kept until the client acknowledges them, so
// a client that reconnects can resume from any slice it has not applied. Bounded: past the limits
// the oldest slices are dropped even unacknowledged, and a client asking for one of those is told
// to resynchronise (a gap).
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>

#include "edgeslam/v1/map_records.pb.h"
#include "util/mutex.h"
#include "wire/slice_sink.h"

namespace edgeslam {

struct SliceQueueLimits {
  std::size_t max_slices = 256;
  std::size_t max_bytes = 64u << 20;          // total encoded bytes kept
  std::size_t max_message_bytes = 64u << 20;  // one slice
};

class SliceQueue final : public SliceSink {
 public:
  explicit SliceQueue(SliceQueueLimits limits = {});

  std::uint64_t push(MapSlice slice) override;
  std::size_t maxSliceBytes() const override { return limits_.max_message_bytes; }
  std::uint64_t acknowledged() const override;

  // The client applied every slice up to `sequence`: they need not be kept any longer.
  void acknowledge(std::uint64_t sequence);

  enum class WaitStatus { kSlice, kTimeout, kClosed, kGap, kBeyondEnd };
  struct WaitResult {
    WaitStatus status = WaitStatus::kTimeout;
    std::shared_ptr<const v1::MapSlice> slice;  // when kSlice
    std::size_t bytes = 0;
  };
  // The first kept slice with sequence >= from, waiting up to `timeout` for one to be pushed.
  // kGap: slices from `from` on were dropped unacknowledged; kBeyondEnd: `from` is more than one
  // past the last slice pushed (the client speaks of slices this session never made).
  WaitResult waitFrom(std::uint64_t from, std::chrono::milliseconds timeout);

  // Wakes every waiter with kClosed, now and later.
  void close();

  // The first sequence a stream can still deliver without a gap.
  std::uint64_t firstAvailable() const;
  std::uint64_t lastPushed() const;
  std::size_t kept() const;
  std::uint64_t droppedUnacknowledged() const;

 private:
  struct Entry {
    std::uint64_t sequence;
    std::shared_ptr<const v1::MapSlice> slice;
    std::size_t bytes;
  };
  void dropFrontLocked(bool acknowledged) REQUIRES(mutex_);

  SliceQueueLimits limits_;
  mutable Mutex mutex_;
  std::condition_variable pushed_;
  std::deque<Entry> entries_ GUARDED_BY(mutex_);
  std::size_t kept_bytes_ GUARDED_BY(mutex_) = 0;
  std::uint64_t last_pushed_ GUARDED_BY(mutex_) = 0;
  std::uint64_t acknowledged_ GUARDED_BY(mutex_) = 0;
  std::uint64_t dropped_through_ GUARDED_BY(mutex_) =
      0;  // highest sequence dropped before acknowledgement
  std::uint64_t dropped_count_ GUARDED_BY(mutex_) = 0;
  bool closed_ GUARDED_BY(mutex_) = false;
};

}  // namespace edgeslam
