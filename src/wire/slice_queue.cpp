#include "wire/slice_queue.h"

#include <fmt/format.h>

#include <algorithm>

#include "wire/wire_convert.h"

namespace edgeslam {

SliceQueue::SliceQueue(SliceQueueLimits limits) : limits_(limits) {}

std::uint64_t SliceQueue::push(MapSlice slice) {
  // Encode outside the lock; the sequence is patched in afterwards.
  auto message = std::make_shared<v1::MapSlice>();
  slice.sequence = 1;
  toProto(slice, message.get());
  MutexLock lock(mutex_);
  const std::uint64_t sequence = last_pushed_ + 1;
  message->set_sequence(sequence);
  const std::size_t bytes = message->ByteSizeLong();
  if (bytes > limits_.max_message_bytes) {
    throw WireError(
        fmt::format("map slice of {} bytes exceeds the {} bytes one message may carry: split it",
                    bytes, limits_.max_message_bytes));
  }
  last_pushed_ = sequence;
  entries_.push_back({sequence, std::move(message), bytes});
  kept_bytes_ += bytes;
  while (entries_.size() > 1 &&
         (entries_.size() > limits_.max_slices || kept_bytes_ > limits_.max_bytes)) {
    dropFrontLocked(false);
  }
  pushed_.notify_all();
  return sequence;
}

std::uint64_t SliceQueue::acknowledged() const {
  MutexLock lock(mutex_);
  return acknowledged_;
}

void SliceQueue::acknowledge(std::uint64_t sequence) {
  MutexLock lock(mutex_);
  sequence = std::min(sequence, last_pushed_);
  if (sequence <= acknowledged_) return;
  acknowledged_ = sequence;
  while (!entries_.empty() && entries_.front().sequence <= acknowledged_) dropFrontLocked(true);
}

void SliceQueue::dropFrontLocked(bool acknowledged) {
  const Entry& front = entries_.front();
  if (!acknowledged) {
    dropped_through_ = std::max(dropped_through_, front.sequence);
    ++dropped_count_;
  }
  kept_bytes_ -= front.bytes;
  entries_.pop_front();
}

SliceQueue::WaitResult SliceQueue::waitFrom(std::uint64_t from, std::chrono::milliseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  MutexLock lock(mutex_);
  from = std::max<std::uint64_t>(from, 1);
  if (from > last_pushed_ + 1) return {WaitStatus::kBeyondEnd, nullptr, 0};
  while (true) {
    // Slices the client already acknowledged are skipped; dropped unacknowledged ones are a gap.
    from = std::max(from, acknowledged_ + 1);
    const auto ready = [&]() REQUIRES(mutex_) { return closed_ || last_pushed_ >= from; };
    if (!lock.waitUntil(pushed_, deadline, ready)) return {WaitStatus::kTimeout, nullptr, 0};
    if (closed_) return {WaitStatus::kClosed, nullptr, 0};
    if (from <= dropped_through_) return {WaitStatus::kGap, nullptr, 0};
    for (const Entry& entry : entries_) {
      if (entry.sequence >= from) return {WaitStatus::kSlice, entry.slice, entry.bytes};
    }
  }
}

void SliceQueue::close() {
  MutexLock lock(mutex_);
  closed_ = true;
  pushed_.notify_all();
}

std::uint64_t SliceQueue::firstAvailable() const {
  MutexLock lock(mutex_);
  return std::max(acknowledged_, dropped_through_) + 1;
}

std::uint64_t SliceQueue::lastPushed() const {
  MutexLock lock(mutex_);
  return last_pushed_;
}

std::size_t SliceQueue::kept() const {
  MutexLock lock(mutex_);
  return entries_.size();
}

std::uint64_t SliceQueue::droppedUnacknowledged() const {
  MutexLock lock(mutex_);
  return dropped_count_;
}

}  // namespace edgeslam
