#include "linkem/link_emulator.h"

#include <poll.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>

#include <algorithm>
#include <random>

#include "linkem/link_connection.h"

namespace edgeslam {

LinkEmulator::LinkEmulator(LinkEmulatorOptions options)
    : options_(std::move(options)), settings_(options_.settings), trace_(options_.trace) {
  validate(settings_);
  if (options_.seed == 0) {
    std::random_device device;
    options_.seed = (static_cast<std::uint64_t>(device()) << 32) ^ device();
  }
}

LinkEmulator::~LinkEmulator() {
  stop();
}

void LinkEmulator::start() {
  MutexLock lifecycle(lifecycle_mutex_);
  if (running_) return;
  listen_fd_ = listenTcp(options_.listen);
  port_ = localPort(listen_fd_.get());
  {
    MutexLock lock(settings_mutex_);
    trace_start_ = LinkClock::now();
  }
  stopping_ = false;
  running_ = true;
  accept_thread_ = std::thread([this] { acceptLoop(); });
  spdlog::debug("link emulator on {}:{} -> {}: {}", options_.listen.host, port_.load(),
                options_.target.toString(), currentSettings().describe());
}

void LinkEmulator::stop() {
  MutexLock lifecycle(lifecycle_mutex_);
  if (!running_) return;
  stopping_ = true;
  if (accept_thread_.joinable()) accept_thread_.join();
  listen_fd_.close();
  std::vector<std::unique_ptr<LinkConnection>> connections;
  {
    MutexLock lock(connections_mutex_);
    connections.swap(connections_);
  }
  for (auto& connection : connections) connection->abort();
  for (auto& connection : connections) connection->join();
  connections.clear();
  running_ = false;
}

void LinkEmulator::setSettings(const LinkSettings& settings) {
  validate(settings);
  MutexLock lock(settings_mutex_);
  settings_ = settings;
}

void LinkEmulator::setTrace(std::optional<LinkTrace> trace) {
  MutexLock lock(settings_mutex_);
  trace_ = std::move(trace);
  trace_start_ = LinkClock::now();
}

LinkSettings LinkEmulator::currentSettings() const {
  MutexLock lock(settings_mutex_);
  if (!trace_) return settings_;
  const double elapsed_s = std::chrono::duration<double>(LinkClock::now() - trace_start_).count();
  return trace_->settingsAt(elapsed_s, settings_);
}

LinkDirectionParams LinkEmulator::directionParams(bool up) const {
  const LinkSettings s = currentSettings();
  LinkDirectionParams params;
  params.delay_ms = up ? s.delay_up_ms : s.delay_down_ms;
  params.mbps = up ? s.up_mbps : s.down_mbps;
  params.jitter_ms = s.jitter_ms;
  params.loss = s.loss;
  params.rtt_ms = s.baseRttMs();
  return params;
}

LinkStats LinkEmulator::stats() const {
  LinkStats stats;
  stats.bytes_up = bytes_up_.load();
  stats.bytes_down = bytes_down_.load();
  stats.connections_total = connections_total_.load();
  stats.connect_failures = connect_failures_.load();
  stats.lost_segments = lost_segments_.load();
  MutexLock lock(connections_mutex_);
  stats.connections_active = static_cast<std::uint64_t>(
      std::count_if(connections_.begin(), connections_.end(),
                    [](const auto& connection) { return !connection->finished(); }));
  return stats;
}

void LinkEmulator::reapFinished() {
  std::vector<std::unique_ptr<LinkConnection>> done;
  {
    MutexLock lock(connections_mutex_);
    auto finished = std::stable_partition(connections_.begin(), connections_.end(),
                                          [](const auto& c) { return !c->finished(); });
    std::move(finished, connections_.end(), std::back_inserter(done));
    connections_.erase(finished, connections_.end());
  }
  done.clear();  // joins the threads (already returned) and closes the sockets
}

void LinkEmulator::acceptLoop() {
  while (!stopping_) {
    pollfd p{listen_fd_.get(), POLLIN, 0};
    const int ready = ::poll(&p, 1, 50);
    reapFinished();
    if (ready <= 0) continue;
    SocketFd client(::accept4(listen_fd_.get(), nullptr, nullptr, SOCK_CLOEXEC));
    if (!client.valid()) continue;
    SocketFd target;
    try {
      target = connectTcp(options_.target, options_.connect_timeout);
    } catch (const std::exception& e) {
      ++connect_failures_;
      spdlog::warn("link emulator: dropping a client: {}", e.what());
      continue;
    }
    setNoDelay(client.get());
    setNoDelay(target.get());
    const std::uint64_t index = next_connection_++;
    auto connection = std::make_unique<LinkConnection>(
        std::move(client), std::move(target), [this] { return directionParams(true); },
        [this] { return directionParams(false); }, LinkPipeCounters{&bytes_up_, &lost_segments_},
        LinkPipeCounters{&bytes_down_, &lost_segments_}, options_.seed + 2 * index,
        options_.max_queue_bytes);
    connection->start();
    ++connections_total_;
    MutexLock lock(connections_mutex_);
    connections_.push_back(std::move(connection));
  }
}

}  // namespace edgeslam
