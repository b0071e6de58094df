#include "wire/edge_server.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <condition_variable>
#include <stdexcept>
#include <thread>

#include "util/mutex.h"
#include "wire/channel_options.h"
#include "wire/edge_service.h"

namespace edgeslam {

namespace {

std::shared_ptr<grpc::ServerCredentials> serverCredentials(const EdgeServerSecurity& security) {
  if (!security.tls()) return grpc::InsecureServerCredentials();
  grpc::SslServerCredentialsOptions options;
  options.pem_key_cert_pairs.push_back(
      {security.tls_private_key_pem, security.tls_certificate_pem});
  return grpc::SslServerCredentials(options);
}

}  // namespace

struct EdgeServer::Impl {
  Impl(const std::string& listen_address, std::shared_ptr<EdgeSessionFactory> session_factory,
       EdgeServerLimits server_limits, EdgeServerSecurity security)
      : limits(server_limits),
        registry(server_limits.max_sessions,
                 SliceQueueLimits{server_limits.max_kept_slices, server_limits.max_kept_slice_bytes,
                                  server_limits.max_send_message_bytes},
                 server_limits.reclaim_idle_after),
        service(registry, std::move(session_factory), server_limits, security.tokens) {
    grpc::ServerBuilder builder;
    builder.AddListeningPort(listen_address, serverCredentials(security), &bound_port);
    builder.RegisterService(&service);
    applyServerChannelOptions(builder, limits.max_message_bytes, limits.max_send_message_bytes);
    server = builder.BuildAndStart();
    if (server == nullptr || bound_port == 0) {
      throw std::runtime_error(fmt::format(
          "edge server: cannot listen at '{}' (address in use or malformed{}?)", listen_address,
          security.tls() ? ", or the TLS certificate and key do not match" : ""));
    }
    const std::size_t colon = listen_address.rfind(':');
    host = colon == std::string::npos ? listen_address : listen_address.substr(0, colon);
    reaper = std::thread([this] { reapIdleSessions(); });
    spdlog::info("edge server: listening at {}:{} ({}, {})", host, bound_port,
                 security.tls() ? "TLS" : "plaintext",
                 security.tokens ? fmt::format("{} client token(s)", security.tokens->size())
                                 : std::string("no client tokens"));
  }

  void reapIdleSessions() EXCLUDES(reaper_mutex) {
    const auto period = std::min<std::chrono::milliseconds>(
        std::chrono::milliseconds(500),
        std::max<std::chrono::milliseconds>(limits.idle_timeout / 4,
                                            std::chrono::milliseconds(10)));
    MutexLock lock(reaper_mutex);
    while (!stopping) {
      lock.waitFor(reaper_wake, period, [&]() REQUIRES(reaper_mutex) { return stopping; });
      if (stopping) break;
      lock.unlock();
      const std::size_t closed = registry.closeIdle(limits.idle_timeout);
      if (closed > 0) {
        spdlog::info("edge server: closed {} idle session(s)", closed);
      }
      lock.lock();
    }
  }

  void shutdown() EXCLUDES(reaper_mutex) {
    {
      MutexLock lock(reaper_mutex);
      if (stopping) return;
      stopping = true;
    }
    reaper_wake.notify_all();
    service.stop();
    registry.closeAll();  // wakes every waiting stream
    server->Shutdown(std::chrono::system_clock::now() + std::chrono::seconds(1));
    server->Wait();
    if (reaper.joinable()) reaper.join();
    spdlog::info("edge server: stopped");
  }

  const EdgeServerLimits limits;
  SessionRegistry registry;
  EdgeService service;
  std::unique_ptr<grpc::Server> server;
  int bound_port = 0;
  std::string host;
  std::thread reaper;
  Mutex reaper_mutex;
  std::condition_variable reaper_wake;
  bool stopping GUARDED_BY(reaper_mutex) = false;
};

EdgeServer::EdgeServer(const std::string& listen_address,
                       std::shared_ptr<EdgeSessionFactory> factory, EdgeServerLimits limits,
                       EdgeServerSecurity security) {
  if (factory == nullptr) throw std::invalid_argument("edge server: no session factory given");
  if (security.tls() == security.tls_private_key_pem.empty()) {
    throw std::invalid_argument("edge server: TLS needs both a certificate and its private key");
  }
  impl_ = std::make_unique<Impl>(listen_address, std::move(factory), limits, std::move(security));
}

EdgeServer::~EdgeServer() {
  shutdown();
}

int EdgeServer::port() const {
  return impl_->bound_port;
}

std::string EdgeServer::address() const {
  return fmt::format("{}:{}", impl_->host, impl_->bound_port);
}

void EdgeServer::shutdown() {
  impl_->shutdown();
}

std::vector<SessionStats> EdgeServer::sessions(bool costs) const {
  return impl_->registry.stats(costs);
}

std::size_t EdgeServer::sessionCount() const {
  return impl_->registry.size();
}

ClosedSessionTotals EdgeServer::closedSessions() const {
  return impl_->registry.closedTotals();
}

std::uint64_t EdgeServer::idleSessionsClosed() const {
  return impl_->registry.idleClosed();
}

}  // namespace edgeslam
