#pragma once
// A loopback TCP server for the link tests: runs `handler(fd)` on its own thread for each
// connection; stop() shuts every socket down and joins.
#include <poll.h>
#include <sys/socket.h>

#include <atomic>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

#include "linkem/socket.h"

namespace edgeslam::test {

class TcpTestServer {
 public:
  using Handler = std::function<void(int fd)>;

  explicit TcpTestServer(Handler handler)
      : handler_(std::move(handler)), listen_(listenTcp({"127.0.0.1", 0})) {
    port_ = localPort(listen_.get());
    accept_thread_ = std::thread([this] { acceptLoop(); });
  }
  ~TcpTestServer() { stop(); }

  std::uint16_t port() const { return port_; }
  HostPort address() const { return {"127.0.0.1", port_}; }

  void stop() {
    if (stopping_.exchange(true)) return;
    accept_thread_.join();
    std::lock_guard lock(mutex_);
    for (const auto& fd : fds_) ::shutdown(fd.get(), SHUT_RDWR);
    for (auto& worker : workers_) worker.join();
    workers_.clear();
    fds_.clear();
  }

 private:
  void acceptLoop() {
    while (!stopping_) {
      pollfd p{listen_.get(), POLLIN, 0};
      if (::poll(&p, 1, 20) <= 0) continue;
      const int fd = ::accept(listen_.get(), nullptr, nullptr);
      if (fd < 0) continue;
      setNoDelay(fd);
      std::lock_guard lock(mutex_);
      fds_.emplace_back(fd);
      workers_.emplace_back([this, fd] { handler_(fd); });
    }
  }

  Handler handler_;
  SocketFd listen_;
  std::uint16_t port_ = 0;
  std::atomic<bool> stopping_{false};
  std::thread accept_thread_;
  std::mutex mutex_;
  std::vector<SocketFd> fds_;
  std::vector<std::thread> workers_;
};

// Reads exactly `size` bytes; false on EOF or error first.
inline bool recvAll(int fd, char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t got = ::recv(fd, data, size, 0);
    if (got <= 0) return false;
    data += got;
    size -= static_cast<std::size_t>(got);
  }
  return true;
}

// Echoes everything back until the peer closes.
inline void echoHandler(int fd) {
  char buffer[16384];
  while (true) {
    const ssize_t got = ::recv(fd, buffer, sizeof buffer, 0);
    if (got <= 0) break;
    if (!sendAll(fd, buffer, static_cast<std::size_t>(got))) break;
  }
  ::shutdown(fd, SHUT_WR);
}

}  // namespace edgeslam::test
