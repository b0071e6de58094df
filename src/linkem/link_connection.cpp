#include "linkem/link_connection.h"

#include <sys/socket.h>

namespace edgeslam {

LinkConnection::LinkConnection(SocketFd client, SocketFd target, LinkPipe::ParamsSource up_params,
                               LinkPipe::ParamsSource down_params, LinkPipeCounters up_counters,
                               LinkPipeCounters down_counters, std::uint64_t seed,
                               std::size_t max_queue_bytes)
    : client_(std::move(client)), target_(std::move(target)) {
  up_ = std::make_unique<LinkPipe>(client_.get(), target_.get(), std::move(up_params), up_counters,
                                   seed, max_queue_bytes, [this] { abort(); });
  down_ = std::make_unique<LinkPipe>(target_.get(), client_.get(), std::move(down_params),
                                     down_counters, seed ^ 0x9e3779b97f4a7c15ULL, max_queue_bytes,
                                     [this] { abort(); });
}

LinkConnection::~LinkConnection() {
  abort();
  join();
}

void LinkConnection::start() {
  up_->start();
  down_->start();
}

void LinkConnection::abort() {
  if (aborted_.exchange(true)) return;
  up_->requestStop();
  down_->requestStop();
  // Wakes threads blocked in recv/send on either socket.
  ::shutdown(client_.get(), SHUT_RDWR);
  ::shutdown(target_.get(), SHUT_RDWR);
}

void LinkConnection::join() {
  up_->join();
  down_->join();
}

}  // namespace edgeslam
