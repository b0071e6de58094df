#pragma once
// A proxied client connection: the client's and the target's sockets with one LinkPipe each way.
#include <atomic>
#include <memory>

#include "linkem/link_pipe.h"
#include "linkem/socket.h"

namespace edgeslam {

class LinkConnection {
 public:
  LinkConnection(SocketFd client, SocketFd target, LinkPipe::ParamsSource up_params,
                 LinkPipe::ParamsSource down_params, LinkPipeCounters up_counters,
                 LinkPipeCounters down_counters, std::uint64_t seed, std::size_t max_queue_bytes);
  ~LinkConnection();
  LinkConnection(const LinkConnection&) = delete;
  LinkConnection& operator=(const LinkConnection&) = delete;

  void start();
  // Tears both directions down (safe from any thread, including the pipes' own).
  void abort();
  void join();
  bool finished() const { return up_->finished() && down_->finished(); }

 private:
  SocketFd client_;
  SocketFd target_;
  std::atomic<bool> aborted_{false};
  std::unique_ptr<LinkPipe> up_;
  std::unique_ptr<LinkPipe> down_;
};

}  // namespace edgeslam
