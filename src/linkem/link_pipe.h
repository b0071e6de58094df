#pragma once
// One direction of a proxied TCP connection: a reader thread takes bytes from `from` and
// schedules them with a LinkDirectionModel; a writer thread hands them to `to` when they are due.
// End of stream is forwarded as a half-close once the bytes before it are delivered.
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <string>
#include <thread>

#include "linkem/link_direction_model.h"
#include "util/mutex.h"

namespace edgeslam {

struct LinkPipeCounters {
  std::atomic<std::uint64_t>* delivered_bytes = nullptr;
  std::atomic<std::uint64_t>* lost_segments = nullptr;
};

class LinkPipe {
 public:
  using ParamsSource = std::function<LinkDirectionParams()>;

  LinkPipe(int from, int to, ParamsSource params, LinkPipeCounters counters, std::uint64_t seed,
           std::size_t max_queue_bytes, std::function<void()> on_failure);
  ~LinkPipe();
  LinkPipe(const LinkPipe&) = delete;
  LinkPipe& operator=(const LinkPipe&) = delete;

  void start();
  // Wakes both threads; the owner also shuts the sockets down so blocking calls return.
  void requestStop();
  void join();
  bool finished() const { return running_threads_.load() == 0; }

 private:
  struct Chunk {
    LinkClock::time_point deliver_at;
    std::string data;
    bool end_of_stream = false;
  };

  void readLoop();
  void writeLoop();
  std::size_t readSize(const LinkDirectionParams& params) const;

  int from_;
  int to_;
  ParamsSource params_;
  LinkPipeCounters counters_;
  LinkDirectionModel model_;  // used by the reader thread only
  std::size_t max_queue_bytes_;
  std::function<void()> on_failure_;

  Mutex mutex_;
  std::condition_variable data_ready_;   // writer waits for due chunks
  std::condition_variable space_ready_;  // reader waits for room in the queue
  std::deque<Chunk> queue_ GUARDED_BY(mutex_);
  std::size_t queued_bytes_ GUARDED_BY(mutex_) = 0;
  bool stop_ GUARDED_BY(mutex_) = false;

  std::atomic<int> running_threads_{0};
  std::thread reader_;
  std::thread writer_;
};

}  // namespace edgeslam
