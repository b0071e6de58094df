#include "linkem/socket.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <memory>
#include <stdexcept>

namespace edgeslam {
namespace {

std::string errnoText(int error) {
  return std::strerror(error);
}

struct AddrInfoDeleter {
  void operator()(addrinfo* info) const { freeaddrinfo(info); }
};
using AddrInfoPtr = std::unique_ptr<addrinfo, AddrInfoDeleter>;

AddrInfoPtr resolve(const HostPort& address, bool passive) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = passive ? AI_PASSIVE : 0;
  addrinfo* result = nullptr;
  const std::string port = std::to_string(address.port);
  const int rc = getaddrinfo(address.host.empty() ? nullptr : address.host.c_str(), port.c_str(),
                             &hints, &result);
  if (rc != 0) {
    throw std::runtime_error(
        fmt::format("cannot resolve {}: {}", address.toString(), gai_strerror(rc)));
  }
  return AddrInfoPtr(result);
}

}  // namespace

std::string HostPort::toString() const {
  if (host.find(':') != std::string::npos) return fmt::format("[{}]:{}", host, port);
  return fmt::format("{}:{}", host, port);
}

HostPort parseHostPort(const std::string& text) {
  const auto colon = text.rfind(':');
  if (colon == std::string::npos || colon + 1 == text.size()) {
    throw std::runtime_error(fmt::format("'{}' is not HOST:PORT", text));
  }
  std::string host = text.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') {
    host = host.substr(1, host.size() - 2);
  }
  const std::string port_text = text.substr(colon + 1);
  unsigned long port = 0;
  std::size_t used = 0;
  try {
    port = std::stoul(port_text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != port_text.size() || port > 65535) {
    throw std::runtime_error(fmt::format("'{}': port '{}' is not in 0..65535", text, port_text));
  }
  if (host.empty()) throw std::runtime_error(fmt::format("'{}': host is empty", text));
  return {host, static_cast<std::uint16_t>(port)};
}

SocketFd& SocketFd::operator=(SocketFd&& other) noexcept {
  if (this != &other) {
    close();
    fd_ = other.release();
  }
  return *this;
}

int SocketFd::release() {
  const int fd = fd_;
  fd_ = -1;
  return fd;
}

void SocketFd::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

SocketFd listenTcp(const HostPort& address, int backlog) {
  const AddrInfoPtr info = resolve(address, true);
  std::string last_error = "no address";
  for (const addrinfo* ai = info.get(); ai != nullptr; ai = ai->ai_next) {
    SocketFd fd(::socket(ai->ai_family, ai->ai_socktype | SOCK_CLOEXEC, ai->ai_protocol));
    if (!fd.valid()) {
      last_error = errnoText(errno);
      continue;
    }
    const int one = 1;
    ::setsockopt(fd.get(), SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    if (::bind(fd.get(), ai->ai_addr, ai->ai_addrlen) != 0 || ::listen(fd.get(), backlog) != 0) {
      last_error = errnoText(errno);
      continue;
    }
    return fd;
  }
  throw std::runtime_error(fmt::format("cannot listen on {}: {}", address.toString(), last_error));
}

SocketFd connectTcp(const HostPort& address, std::chrono::milliseconds timeout) {
  const AddrInfoPtr info = resolve(address, false);
  std::string last_error = "no address";
  for (const addrinfo* ai = info.get(); ai != nullptr; ai = ai->ai_next) {
    SocketFd fd(
        ::socket(ai->ai_family, ai->ai_socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, ai->ai_protocol));
    if (!fd.valid()) {
      last_error = errnoText(errno);
      continue;
    }
    int rc = ::connect(fd.get(), ai->ai_addr, ai->ai_addrlen);
    if (rc != 0 && errno == EINPROGRESS) {
      pollfd p{fd.get(), POLLOUT, 0};
      rc = ::poll(&p, 1, static_cast<int>(timeout.count()));
      if (rc == 0) {
        last_error = "timed out";
        continue;
      }
      int error = 0;
      socklen_t length = sizeof error;
      ::getsockopt(fd.get(), SOL_SOCKET, SO_ERROR, &error, &length);
      if (rc < 0 || error != 0) {
        last_error = errnoText(rc < 0 ? errno : error);
        continue;
      }
      rc = 0;
    }
    if (rc != 0) {
      last_error = errnoText(errno);
      continue;
    }
    const int flags = 0;  // back to blocking mode
    if (::fcntl(fd.get(), F_SETFL, flags) != 0) {
      last_error = errnoText(errno);
      continue;
    }
    return fd;
  }
  throw std::runtime_error(fmt::format("cannot connect to {}: {}", address.toString(), last_error));
}

std::uint16_t localPort(int fd) {
  sockaddr_storage storage{};
  socklen_t length = sizeof storage;
  if (::getsockname(fd, reinterpret_cast<sockaddr*>(&storage), &length) != 0) {
    throw std::runtime_error(fmt::format("getsockname failed: {}", errnoText(errno)));
  }
  if (storage.ss_family == AF_INET) {
    return ntohs(reinterpret_cast<const sockaddr_in*>(&storage)->sin_port);
  }
  return ntohs(reinterpret_cast<const sockaddr_in6*>(&storage)->sin6_port);
}

void setNoDelay(int fd) {
  const int one = 1;
  ::setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
}

bool sendAll(int fd, const char* data, std::size_t size) {
  while (size > 0) {
    const ssize_t sent = ::send(fd, data, size, MSG_NOSIGNAL);
    if (sent < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += sent;
    size -= static_cast<std::size_t>(sent);
  }
  return true;
}

}  // namespace edgeslam
