#include "wire/slice_queue.h"

#include <gtest/gtest.h>

#include <thread>

#include "wire/wire_error.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;
using Status = SliceQueue::WaitStatus;

MapSlice sliceWithErased(int erased) {
  MapSlice slice;
  slice.sequence = 999;  // replaced by the queue
  for (int i = 0; i < erased; ++i) slice.points_erased.push_back(static_cast<MapPointId>(i + 1));
  return slice;
}

TEST(SliceQueue, AssignsSequencesAndDeliversInOrder) {
  SliceQueue queue;
  EXPECT_EQ(queue.push(sliceWithErased(1)), 1u);
  EXPECT_EQ(queue.push(sliceWithErased(2)), 2u);
  const auto first = queue.waitFrom(1, 10ms);
  ASSERT_EQ(first.status, Status::kSlice);
  EXPECT_EQ(first.slice->sequence(), 1u);
  EXPECT_EQ(first.slice->points_erased_size(), 1);
  EXPECT_EQ(first.bytes, first.slice->ByteSizeLong());
  const auto second = queue.waitFrom(2, 10ms);
  ASSERT_EQ(second.status, Status::kSlice);
  EXPECT_EQ(second.slice->sequence(), 2u);
  EXPECT_EQ(queue.waitFrom(3, 10ms).status, Status::kTimeout);
  EXPECT_EQ(queue.waitFrom(5, 10ms).status, Status::kBeyondEnd);
}

TEST(SliceQueue, KeepsUntilAcknowledgedAndSkipsAcknowledged) {
  SliceQueue queue;
  for (int i = 0; i < 5; ++i) queue.push(sliceWithErased(1));
  queue.acknowledge(3);
  EXPECT_EQ(queue.kept(), 2u);
  EXPECT_EQ(queue.acknowledged(), 3u);
  const auto resumed = queue.waitFrom(1, 10ms);  // a client behind its own acknowledgement
  ASSERT_EQ(resumed.status, Status::kSlice);
  EXPECT_EQ(resumed.slice->sequence(), 4u);
  queue.acknowledge(100);  // clamped to what exists
  EXPECT_EQ(queue.acknowledged(), 5u);
  EXPECT_EQ(queue.kept(), 0u);
  EXPECT_EQ(queue.droppedUnacknowledged(), 0u);
}

TEST(SliceQueue, BoundedWithGapReported) {
  SliceQueue queue(SliceQueueLimits{3, 1u << 20, 1u << 20});
  for (int i = 0; i < 6; ++i) queue.push(sliceWithErased(1));
  EXPECT_EQ(queue.kept(), 3u);
  EXPECT_EQ(queue.droppedUnacknowledged(), 3u);
  EXPECT_EQ(queue.waitFrom(2, 10ms).status, Status::kGap);
  EXPECT_EQ(queue.firstAvailable(), 4u);
  const auto available = queue.waitFrom(4, 10ms);
  ASSERT_EQ(available.status, Status::kSlice);
  EXPECT_EQ(available.slice->sequence(), 4u);
}

TEST(SliceQueue, RefusesSlicesLargerThanOneMessage) {
  SliceQueue queue(SliceQueueLimits{8, 1u << 20, 100});
  EXPECT_THROW(queue.push(sliceWithErased(200)), WireError);  // ~200 bytes: ids travel as deltas
  EXPECT_EQ(queue.lastPushed(), 0u);
}

TEST(SliceQueue, WaiterWakesOnPushAndOnClose) {
  SliceQueue queue;
  std::thread pusher([&] {
    std::this_thread::sleep_for(50ms);
    queue.push(sliceWithErased(1));
  });
  const auto pushed = queue.waitFrom(1, 10s);
  pusher.join();
  EXPECT_EQ(pushed.status, Status::kSlice);

  std::thread closer([&] {
    std::this_thread::sleep_for(50ms);
    queue.close();
  });
  const auto start = std::chrono::steady_clock::now();
  EXPECT_EQ(queue.waitFrom(2, 10s).status, Status::kClosed);
  closer.join();
  EXPECT_LT(std::chrono::steady_clock::now() - start, 5s);
}

}  // namespace
}  // namespace edgeslam
