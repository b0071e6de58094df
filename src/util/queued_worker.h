#pragma once
// A queue of items worked off one at a time, on a thread of its own (start) or on the caller's
// (processAll): the one way edgeslam's background workers run. Local mapping, loop closing and
// keyframe segmentation differ in what they do with an item, never in how they take one, pause,
// stop, wait for idleness or fail.
//
// An exception escaping the work ends the worker alone (util/worker_thread.h): its queue is
// emptied, later pushes are refused, whoever waits in waitUntilIdle() or pause() returns, and the
// owner's failure handler hears the cause once, on the worker's thread. Unthreaded, processAll()
// lets the exception reach its caller.
#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <optional>
#include <string>
#include <utility>

#include "util/mutex.h"
#include "util/worker_thread.h"

namespace edgeslam {

template <class Item>
struct QueuedWorkerOptions {
  // 0: unbounded. Otherwise a push beyond it drops the oldest waiting item (counted in dropped()).
  std::size_t capacity = 0;
  // Take the newest waiting item first (the older ones wait until the worker has time).
  bool newest_first = false;
  // Nice increment for the thread (util/thread_priority.h); 0 leaves it as it is.
  int thread_nice = 0;
  WorkerThread::FailureHandler on_failure;
  // Items of different groups (the clients of one shared map) do not make each other give way:
  // a push raises giveWay() only when it is of the group of the item in hand, or when it makes
  // `backlog` items wait (0: never). No group function: one group.
  std::function<std::uint64_t(const Item&)> group;
  std::size_t backlog = 0;
};

template <class Item>
class QueuedWorker {
 public:
  using Work = std::function<void(Item)>;

  // `name` says what the work is ("local mapping"): the failure cause reads "<name> failed: ...".
  QueuedWorker(std::string name, Work work, QueuedWorkerOptions<Item> options = {})
      : name_(std::move(name)), work_(std::move(work)), options_(std::move(options)) {}
  ~QueuedWorker() { stop(); }
  QueuedWorker(const QueuedWorker&) = delete;
  QueuedWorker& operator=(const QueuedWorker&) = delete;

  // Starts the thread; a no-op while one runs (or has failed and was not stopped since).
  void start() {
    {
      MutexLock lock(mutex_);
      if (started_) return;
      started_ = true;
      stopping_ = false;
      failed_ = false;
    }
    thread_.start(
        name_, [this] { run(); }, [this](const std::string& cause) { fail(cause); },
        options_.thread_nice);
  }

  // Ends the thread after the item in hand and joins it; items still queued stay queued (for
  // processAll), further pushes are refused until start().
  void stop() {
    {
      MutexLock lock(mutex_);
      stopping_ = true;
      give_way_ = true;
    }
    wake_.notify_all();
    idle_.notify_all();
    thread_.join();
    MutexLock lock(mutex_);
    started_ = false;
  }

  // Any thread. false when refused: the worker failed or was stopped.
  bool push(Item item) {
    {
      MutexLock lock(mutex_);
      if (failed_ || stopping_) return false;
      const bool same_group = !group_in_hand_ || groupOf(item) == *group_in_hand_;
      queue_.push_back(std::move(item));
      if (options_.capacity > 0 && queue_.size() > options_.capacity) {
        queue_.pop_front();
        ++dropped_;
      }
      if (same_group || (options_.backlog > 0 && queue_.size() >= options_.backlog)) {
        give_way_ = true;
      }
    }
    wake_.notify_one();
    return true;
  }

  // Works off every queued item on the caller's thread (for a worker that was not started).
  void processAll() {
    while (std::optional<Item> item = takeNow()) work_(std::move(*item));
  }

  // Threaded: returns once the queue is empty and no item is in hand, or the worker failed or is
  // stopping. Returns at once when no thread was started.
  void waitUntilIdle() {
    MutexLock lock(mutex_);
    lock.wait(idle_, [this]() REQUIRES(mutex_) {
      return !started_ || failed_ || stopping_ || (queue_.empty() && !busy_);
    });
  }

  // The thread takes no item until every pause() has had its resume() (two threads may each hold
  // the worker paused, e.g. a loop correction and a global BA's write-back); returns once the item
  // in hand (if any) is done.
  void pause() {
    MutexLock lock(mutex_);
    ++pauses_;
    give_way_ = true;
    lock.wait(idle_, [this]() REQUIRES(mutex_) { return !busy_; });
  }
  void resume() {
    {
      MutexLock lock(mutex_);
      if (pauses_ > 0) --pauses_;
      if (pauses_ > 0) return;
    }
    wake_.notify_all();
  }

  void clear() {
    MutexLock lock(mutex_);
    queue_.clear();
  }

  // Set while the item in hand should give way: an item was pushed, pause() or stop() was called.
  // Cleared as each item is taken. Long work (a bundle adjustment) polls it.
  const std::atomic<bool>* giveWay() const { return &give_way_; }

  // Started and not stopped since (also after a failure, until stop()).
  bool running() const {
    MutexLock lock(mutex_);
    return started_;
  }
  bool empty() const {
    MutexLock lock(mutex_);
    return queue_.empty();
  }
  // An item of `item`'s group waits (any item, without groups).
  bool hasQueuedOfGroup(const Item& item) const {
    MutexLock lock(mutex_);
    const std::uint64_t group = groupOf(item);
    return std::any_of(queue_.begin(), queue_.end(),
                       [&](const Item& queued) { return groupOf(queued) == group; });
  }
  std::size_t size() const {
    MutexLock lock(mutex_);
    return queue_.size();
  }
  std::size_t dropped() const {
    MutexLock lock(mutex_);
    return dropped_;
  }
  bool failed() const {
    MutexLock lock(mutex_);
    return failed_;
  }
  std::optional<std::string> failure() const { return thread_.failure(); }

 private:
  void run() {
    while (true) {
      std::optional<Item> item;
      {
        MutexLock lock(mutex_);
        busy_ = false;
        idle_.notify_all();
        lock.wait(wake_, [this]() REQUIRES(mutex_) {
          return stopping_ || (pauses_ == 0 && !queue_.empty());
        });
        if (stopping_) return;
        item.emplace(popNext());
        busy_ = true;
        give_way_ = false;
        group_in_hand_ = groupOf(*item);
      }
      work_(std::move(*item));
    }
  }

  std::optional<Item> takeNow() {
    MutexLock lock(mutex_);
    if (queue_.empty()) return std::nullopt;
    std::optional<Item> item(popNext());
    give_way_ = false;
    group_in_hand_ = groupOf(*item);
    return item;
  }

  std::uint64_t groupOf(const Item& item) const {
    return options_.group ? options_.group(item) : 0;
  }

  Item popNext() REQUIRES(mutex_) {
    if (options_.newest_first) {
      Item item(std::move(queue_.back()));
      queue_.pop_back();
      return item;
    }
    Item item(std::move(queue_.front()));
    queue_.pop_front();
    return item;
  }

  void fail(const std::string& cause) {
    {
      MutexLock lock(mutex_);
      failed_ = true;
      busy_ = false;
      queue_.clear();
    }
    idle_.notify_all();
    if (options_.on_failure) options_.on_failure(cause);
  }

  const std::string name_;
  const Work work_;
  const QueuedWorkerOptions<Item> options_;

  mutable Mutex mutex_;
  std::condition_variable wake_;  // an item, resume() or stop() for the thread
  std::condition_variable idle_;  // the thread is between items, or failed, or stopping
  std::deque<Item> queue_ GUARDED_BY(mutex_);
  std::size_t dropped_ GUARDED_BY(mutex_) = 0;
  bool started_ GUARDED_BY(mutex_) = false;
  bool busy_ GUARDED_BY(mutex_) = false;
  int pauses_ GUARDED_BY(mutex_) = 0;
  bool stopping_ GUARDED_BY(mutex_) = false;
  bool failed_ GUARDED_BY(mutex_) = false;
  std::optional<std::uint64_t> group_in_hand_ GUARDED_BY(mutex_);  // the last item taken's
  std::atomic<bool> give_way_{false};
  WorkerThread thread_;
};

}  // namespace edgeslam
