#include "util/worker_thread.h"

#include <spdlog/spdlog.h>

#include <exception>
#include <utility>

#include "util/thread_priority.h"

namespace edgeslam {

void WorkerThread::start(std::string name, std::function<void()> body, FailureHandler on_failure,
                         int nice) {
  join();
  {
    MutexLock lock(mutex_);
    failure_.reset();
  }
  thread_ = std::thread([this, name = std::move(name), body = std::move(body),
                         on_failure = std::move(on_failure), nice] {
    if (!lowerCurrentThreadPriority(nice)) {
      spdlog::warn("{}: could not lower the thread's priority by {}", name, nice);
    }
    std::string cause;
    try {
      body();
      return;
    } catch (const std::exception& e) {
      cause = name + " failed: " + e.what();
    } catch (...) {
      cause = name + " failed: an unknown exception";
    }
    spdlog::error("{}", cause);
    {
      MutexLock lock(mutex_);
      failure_ = cause;
    }
    if (on_failure) on_failure(cause);
  });
}

void WorkerThread::join() {
  if (thread_.joinable() && thread_.get_id() != std::this_thread::get_id()) thread_.join();
}

std::optional<std::string> WorkerThread::failure() const {
  MutexLock lock(mutex_);
  return failure_;
}

}  // namespace edgeslam
