#pragma once
// A background thread that catches what escapes its body. Without it, an exception in one
// session's mapping thread reaches std::terminate and takes the whole edge server, every other
// session with it. The cause goes to the owner (which ends that session or run with it) and stays
// readable as failure().
#include <functional>
#include <optional>
#include <string>
#include <thread>

#include "util/mutex.h"

namespace edgeslam {

class WorkerThread {
 public:
  // Called on the worker's own thread, once, after the body threw; the thread ends after it.
  using FailureHandler = std::function<void(const std::string& cause)>;

  WorkerThread() = default;
  ~WorkerThread() { join(); }
  WorkerThread(const WorkerThread&) = delete;
  WorkerThread& operator=(const WorkerThread&) = delete;

  // `name` says what the worker does ("local mapping"): the cause reads "<name> failed: <what>".
  // `nice` > 0 lowers the thread's priority by that much first (util/thread_priority.h; a refusal
  // is logged, not fatal). A worker that is still joinable is joined first.
  void start(std::string name, std::function<void()> body, FailureHandler on_failure = {},
             int nice = 0);
  void join();
  bool joinable() const { return thread_.joinable(); }
  std::optional<std::string> failure() const;

 private:
  std::thread thread_;
  mutable Mutex mutex_;
  std::optional<std::string> failure_ GUARDED_BY(mutex_);
};

}  // namespace edgeslam
