#pragma once
// Thin POSIX TCP helpers for the link emulator: an owning file descriptor, HOST:PORT parsing,
// listening and connecting with a timeout. Errors throw std::runtime_error naming the address.
#include <chrono>
#include <cstdint>
#include <string>

namespace edgeslam {

struct HostPort {
  std::string host;
  std::uint16_t port = 0;
  std::string toString() const;
};

// "host:port" (host may be a name, an IPv4 address or "[IPv6]"); port 0 is allowed.
HostPort parseHostPort(const std::string& text);

class SocketFd {
 public:
  SocketFd() = default;
  explicit SocketFd(int fd) : fd_(fd) {}
  ~SocketFd() { close(); }
  SocketFd(SocketFd&& other) noexcept : fd_(other.release()) {}
  SocketFd& operator=(SocketFd&& other) noexcept;
  SocketFd(const SocketFd&) = delete;
  SocketFd& operator=(const SocketFd&) = delete;

  int get() const { return fd_; }
  bool valid() const { return fd_ >= 0; }
  int release();
  void close();

 private:
  int fd_ = -1;
};

SocketFd listenTcp(const HostPort& address, int backlog = 128);
SocketFd connectTcp(const HostPort& address, std::chrono::milliseconds timeout);
std::uint16_t localPort(int fd);
// Disables Nagle's algorithm: the emulator decides when bytes leave, not the kernel.
void setNoDelay(int fd);
// Sends everything (retrying on EINTR and short writes); false when the peer is gone.
bool sendAll(int fd, const char* data, std::size_t size);

}  // namespace edgeslam
