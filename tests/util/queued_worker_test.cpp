// The one worker every background stage runs on: items are worked off in order, idleness means
// nothing queued and nothing in hand, stop leaves the queue to the owner, a full queue drops its
// oldest item, and an exception ends the worker alone (cause reported once, queue cleared, pushes
// refused, waiters woken).
#include "util/queued_worker.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <future>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

#include "util/thread_priority.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;

// What the work saw, readable from the test's thread.
struct Record {
  Mutex mutex;
  std::vector<int> items GUARDED_BY(mutex);
  std::vector<std::thread::id> threads GUARDED_BY(mutex);

  void add(int item) {
    MutexLock lock(mutex);
    items.push_back(item);
    threads.push_back(std::this_thread::get_id());
  }
  std::vector<int> seen() {
    MutexLock lock(mutex);
    return items;
  }
  std::vector<std::thread::id> seenOn() {
    MutexLock lock(mutex);
    return threads;
  }
};

// Generous: only a broken worker ever reaches it.
constexpr auto kHang = 10s;

bool becomesTrue(const std::atomic<bool>& flag) {
  const auto deadline = std::chrono::steady_clock::now() + kHang;
  while (!flag.load()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(1ms);
  }
  return true;
}

TEST(QueuedWorker, WorksOffItemsInOrderOnItsOwnThread) {
  Record record;
  QueuedWorker<int> worker("counting", [&](int item) { record.add(item); });
  worker.start();
  std::vector<int> pushed;
  for (int i = 0; i < 200; ++i) {
    EXPECT_TRUE(worker.push(i));
    pushed.push_back(i);
  }
  worker.waitUntilIdle();
  EXPECT_EQ(record.seen(), pushed);
  for (const std::thread::id id : record.seenOn()) EXPECT_NE(id, std::this_thread::get_id());
  EXPECT_TRUE(worker.empty());
  EXPECT_EQ(worker.dropped(), 0u);
  EXPECT_TRUE(worker.running());
  worker.stop();
  EXPECT_FALSE(worker.running());
  EXPECT_FALSE(worker.failure().has_value());
}

TEST(QueuedWorker, WaitUntilIdleWaitsForTheItemInHand) {
  Record record;
  std::promise<void> gate;
  std::shared_future<void> opened = gate.get_future().share();
  std::atomic<bool> in_hand{false};
  QueuedWorker<int> worker("gated", [&](int item) {
    in_hand = true;
    opened.wait();
    record.add(item);
  });
  worker.start();
  worker.push(1);
  ASSERT_TRUE(becomesTrue(in_hand));  // the queue is empty now, the item still in hand
  auto idle = std::async(std::launch::async, [&] { worker.waitUntilIdle(); });
  EXPECT_EQ(idle.wait_for(100ms), std::future_status::timeout);
  gate.set_value();
  ASSERT_EQ(idle.wait_for(kHang), std::future_status::ready);
  EXPECT_EQ(record.seen(), std::vector<int>{1});
}

TEST(QueuedWorker, StopEndsAfterTheItemInHandAndLeavesTheRestQueued) {
  Record record;
  std::atomic<bool> in_hand{false};
  QueuedWorker<int>* self = nullptr;
  QueuedWorker<int> worker("stoppable", [&](int item) {
    if (item == 1 && !in_hand.exchange(true)) {
      // Only stop() raises the flag now: every item was queued before start().
      EXPECT_TRUE(becomesTrue(*self->giveWay()));
    }
    record.add(item);
  });
  self = &worker;
  for (int i = 1; i <= 3; ++i) ASSERT_TRUE(worker.push(i));
  worker.start();
  ASSERT_TRUE(becomesTrue(in_hand));
  worker.stop();
  EXPECT_EQ(record.seen(), std::vector<int>{1});
  EXPECT_EQ(worker.size(), 2u);
  EXPECT_FALSE(worker.running());
  EXPECT_FALSE(worker.push(4));  // refused once stopped
  worker.waitUntilIdle();        // no thread: returns at once
  worker.processAll();           // the owner may still work off what was left, on its thread
  EXPECT_EQ(record.seen(), (std::vector<int>{1, 2, 3}));
  EXPECT_EQ(record.seenOn().back(), std::this_thread::get_id());
}

TEST(QueuedWorker, ItsThreadRunsAtTheGivenNiceIncrement) {
  std::atomic<int> nice{-100};
  QueuedWorker<int> worker(
      "background", [&](int) { nice = currentThreadNice(); },
      {.capacity = 0, .thread_nice = 3, .on_failure = {}, .group = {}, .backlog = 0});
  worker.start();
  worker.push(1);
  worker.waitUntilIdle();
  EXPECT_EQ(nice.load(), std::min(19, currentThreadNice() + 3));
}

TEST(QueuedWorker, AFullQueueDropsItsOldestItemAndCountsIt) {
  Record record;
  QueuedWorker<int> worker(
      "bounded", [&](int item) { record.add(item); },
      {.capacity = 2, .thread_nice = 0, .on_failure = {}, .group = {}, .backlog = 0});
  for (int i = 1; i <= 5; ++i) EXPECT_TRUE(worker.push(i));
  EXPECT_EQ(worker.size(), 2u);
  EXPECT_EQ(worker.dropped(), 3u);
  worker.processAll();  // unthreaded: on the caller's thread
  EXPECT_EQ(record.seen(), (std::vector<int>{4, 5}));
  EXPECT_EQ(record.seenOn(), std::vector<std::thread::id>(2, std::this_thread::get_id()));
}

TEST(QueuedWorker, NewestFirstTakesTheLatestItemAndDropsTheOldestBeyondItsBound) {
  Record record;
  QueuedWorker<int> worker("newest first", [&](int item) { record.add(item); },
                           {.capacity = 3,
                            .newest_first = true,
                            .thread_nice = 0,
                            .on_failure = {},
                            .group = {},
                            .backlog = 0});
  for (int i = 1; i <= 5; ++i) EXPECT_TRUE(worker.push(i));
  EXPECT_EQ(worker.dropped(), 2u);
  worker.processAll();
  EXPECT_EQ(record.seen(), (std::vector<int>{5, 4, 3}));
}

TEST(QueuedWorker, PauseHoldsItemsUntilResume) {
  Record record;
  QueuedWorker<int> worker("pausable", [&](int item) { record.add(item); });
  worker.start();
  worker.pause();
  worker.push(7);
  std::this_thread::sleep_for(100ms);
  EXPECT_TRUE(record.seen().empty());
  EXPECT_EQ(worker.size(), 1u);
  worker.resume();
  worker.waitUntilIdle();
  EXPECT_EQ(record.seen(), std::vector<int>{7});
}

// A loop correction and a global BA's write-back may each hold the local mapper paused at once:
// the first resume must not let the worker go while the other still holds it.
TEST(QueuedWorker, PausesAreCountedUntilEachIsResumed) {
  Record record;
  QueuedWorker<int> worker("paused twice", [&](int item) { record.add(item); });
  worker.start();
  worker.pause();
  worker.pause();
  worker.push(7);
  worker.resume();
  std::this_thread::sleep_for(100ms);
  EXPECT_TRUE(record.seen().empty()) << "one pause was still held";
  worker.resume();
  worker.waitUntilIdle();
  EXPECT_EQ(record.seen(), std::vector<int>{7});
}

TEST(QueuedWorker, PauseWaitsForTheItemInHandAndAsksItToGiveWay) {
  std::atomic<bool> in_hand{false};
  std::atomic<bool> gave_way{false};
  QueuedWorker<int>* self = nullptr;
  QueuedWorker<int> worker("yielding", [&](int) {
    in_hand = true;
    gave_way = becomesTrue(*self->giveWay());
  });
  self = &worker;
  worker.push(1);
  worker.start();
  ASSERT_TRUE(becomesTrue(in_hand));
  worker.pause();  // returns only once the item gave way
  EXPECT_TRUE(gave_way.load());
  worker.resume();
}

// A started worker holding item 11 in hand until release(). Grouped: the groups are the tens
// (11 and 12 are one client's, 21 another's), and a backlog of 3 waiting items gives way too.
class HeldItem {
 public:
  explicit HeldItem(bool grouped)
      : worker_("held",
                [this](int item) {
                  if (item != 11) return;
                  in_hand_ = true;
                  opened_.wait();
                },
                {.capacity = 0,
                 .newest_first = false,
                 .thread_nice = 0,
                 .on_failure = {},
                 .group = grouped ? [](const int& item) -> std::uint64_t {
                   return static_cast<std::uint64_t>(item / 10);
                 }
                 : std::function<std::uint64_t(const int&)>{},
                 .backlog = grouped ? 3u : 0u}) {
    worker_.push(11);
    worker_.start();
  }
  ~HeldItem() {
    release();
    worker_.waitUntilIdle();
  }
  bool inHand() const { return becomesTrue(in_hand_); }
  QueuedWorker<int>& worker() { return worker_; }
  bool givesWay() const { return worker_.giveWay()->load(); }
  void release() {
    if (!released_) gate_.set_value();
    released_ = true;
  }

 private:
  std::atomic<bool> in_hand_{false};
  std::promise<void> gate_;
  std::shared_future<void> opened_ = gate_.get_future().share();
  bool released_ = false;
  QueuedWorker<int> worker_;  // last: its thread uses the above
};

TEST(QueuedWorker, AnItemOfAnotherGroupDoesNotMakeTheItemInHandGiveWay) {
  HeldItem held(true);
  ASSERT_TRUE(held.inHand());
  held.worker().push(21);
  EXPECT_FALSE(held.givesWay());
  EXPECT_TRUE(held.worker().hasQueuedOfGroup(21));
  EXPECT_FALSE(held.worker().hasQueuedOfGroup(11));
  held.worker().push(12);
  EXPECT_TRUE(held.givesWay());
  EXPECT_TRUE(held.worker().hasQueuedOfGroup(11));
}

TEST(QueuedWorker, ABacklogOfOtherGroupsMakesTheItemInHandGiveWay) {
  HeldItem held(true);
  ASSERT_TRUE(held.inHand());
  held.worker().push(21);
  held.worker().push(31);
  EXPECT_FALSE(held.givesWay());
  held.worker().push(41);  // three waiting
  EXPECT_TRUE(held.givesWay());
}

TEST(QueuedWorker, WithoutGroupsEveryPushMakesTheItemInHandGiveWay) {
  HeldItem held(false);
  ASSERT_TRUE(held.inHand());
  EXPECT_FALSE(held.worker().hasQueuedOfGroup(11));
  held.worker().push(21);
  EXPECT_TRUE(held.givesWay());
  EXPECT_TRUE(held.worker().hasQueuedOfGroup(11));
}

TEST(QueuedWorker, AnExceptionEndsTheWorkerAlone) {
  Record record;
  std::promise<void> gate;
  std::shared_future<void> opened = gate.get_future().share();
  std::atomic<bool> in_hand{false};
  Mutex reports_mutex;
  std::vector<std::string> reports;
  std::thread::id reported_on;
  QueuedWorker<int> worker("counting",
                           [&](int item) {
                             if (item == 2) {
                               in_hand = true;
                               opened.wait();
                               throw std::runtime_error("bad item 2");
                             }
                             record.add(item);
                           },
                           {.capacity = 0,
                            .thread_nice = 0,
                            .on_failure =
                                [&](const std::string& cause) {
                                  MutexLock lock(reports_mutex);
                                  reports.push_back(cause);
                                  reported_on = std::this_thread::get_id();
                                },
                            .group = {},
                            .backlog = 0});
  for (int i = 1; i <= 4; ++i) ASSERT_TRUE(worker.push(i));
  worker.start();
  ASSERT_TRUE(becomesTrue(in_hand));
  // Waiting while the failing item is in hand and two more are queued: the failure must wake it.
  auto idle = std::async(std::launch::async, [&] { worker.waitUntilIdle(); });
  EXPECT_EQ(idle.wait_for(100ms), std::future_status::timeout);  // it waits, asleep
  gate.set_value();
  if (idle.wait_for(kHang) != std::future_status::ready) {
    worker.stop();  // wakes the waiter, so that the test ends
    FAIL() << "the failure did not wake waitUntilIdle()";
  }

  EXPECT_TRUE(worker.failed());
  ASSERT_TRUE(worker.failure().has_value());
  EXPECT_EQ(*worker.failure(), "counting failed: bad item 2");
  EXPECT_EQ(worker.size(), 0u);  // 3 and 4 were cleared, never worked
  EXPECT_FALSE(worker.push(5));  // refused
  EXPECT_EQ(worker.size(), 0u);
  worker.waitUntilIdle();  // returns at once
  worker.pause();          // nothing in hand: returns at once
  worker.resume();
  EXPECT_TRUE(worker.running());  // until the owner stops it
  worker.start();                 // no restart of a failed worker that was not stopped
  worker.stop();
  EXPECT_EQ(record.seen(), std::vector<int>{1});
  MutexLock lock(reports_mutex);
  ASSERT_EQ(reports.size(), 1u);
  EXPECT_EQ(reports[0], "counting failed: bad item 2");
  EXPECT_NE(reported_on, std::this_thread::get_id());
}

TEST(QueuedWorker, UnthreadedAnExceptionReachesTheCaller) {
  Record record;
  QueuedWorker<int> worker("inline", [&](int item) {
    if (item == 2) throw std::runtime_error("bad item 2");
    record.add(item);
  });
  for (int i = 1; i <= 3; ++i) worker.push(i);
  EXPECT_THROW(worker.processAll(), std::runtime_error);
  EXPECT_EQ(record.seen(), std::vector<int>{1});
  EXPECT_FALSE(worker.failed());
  worker.processAll();  // the rest is still there for the caller
  EXPECT_EQ(record.seen(), (std::vector<int>{1, 3}));
}

}  // namespace
}  // namespace edgeslam
