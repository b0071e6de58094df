#pragma once
// A TCP proxy that puts an emulated wireless link between its clients and a target: listens on
// HOST:PORT, connects each accepted client to the target, and forwards both directions through a
// LinkDirectionModel ("up" = client -> target). Settings can change while running, directly or
// by replaying a LinkTrace. start() and stop() are thread-safe; stop() closes every connection
// and returns promptly.
#include <atomic>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "linkem/link_direction_model.h"
#include "linkem/link_settings.h"
#include "linkem/link_trace.h"
#include "linkem/socket.h"
#include "util/mutex.h"

namespace edgeslam {

struct LinkEmulatorOptions {
  HostPort listen{"127.0.0.1", 0};  // port 0: the system picks a free port (see port())
  HostPort target{"127.0.0.1", 0};
  LinkSettings settings;
  std::optional<LinkTrace> trace;  // replayed from start(), looping; overrides `settings`
  std::uint64_t seed = 0;          // jitter and loss draws; 0 = random
  std::size_t max_queue_bytes = 8 * 1024 * 1024;  // per direction and connection
  std::chrono::milliseconds connect_timeout{2000};
};

struct LinkStats {
  std::uint64_t bytes_up = 0;  // delivered to the target
  std::uint64_t bytes_down = 0;
  std::uint64_t connections_total = 0;
  std::uint64_t connections_active = 0;
  std::uint64_t connect_failures = 0;  // clients dropped because the target refused
  std::uint64_t lost_segments = 0;     // emulated losses (both directions)
};

class LinkConnection;

class LinkEmulator {
 public:
  explicit LinkEmulator(LinkEmulatorOptions options);
  ~LinkEmulator();
  LinkEmulator(const LinkEmulator&) = delete;
  LinkEmulator& operator=(const LinkEmulator&) = delete;

  // Binds and starts accepting; throws std::runtime_error when the address cannot be bound.
  void start();
  void stop();
  bool running() const { return running_.load(); }
  // The bound port (valid after start()).
  std::uint16_t port() const { return port_.load(); }

  // Applies to bytes read from now on. Throws std::invalid_argument for invalid settings.
  void setSettings(const LinkSettings& settings);
  void setTrace(std::optional<LinkTrace> trace);
  // The settings in effect now (the trace's values when one is replayed).
  LinkSettings currentSettings() const;
  LinkStats stats() const;

 private:
  void acceptLoop();
  void reapFinished();
  LinkDirectionParams directionParams(bool up) const;

  LinkEmulatorOptions options_;
  Mutex lifecycle_mutex_;
  std::atomic<bool> running_{false};
  std::atomic<bool> stopping_{false};
  std::atomic<std::uint16_t> port_{0};
  SocketFd listen_fd_;
  std::thread accept_thread_ GUARDED_BY(lifecycle_mutex_);

  mutable Mutex settings_mutex_;
  LinkSettings settings_ GUARDED_BY(settings_mutex_);
  std::optional<LinkTrace> trace_ GUARDED_BY(settings_mutex_);
  LinkClock::time_point trace_start_ GUARDED_BY(settings_mutex_);

  mutable Mutex connections_mutex_;
  std::vector<std::unique_ptr<LinkConnection>> connections_ GUARDED_BY(connections_mutex_);
  std::uint64_t next_connection_ = 0;  // the accept thread's alone

  std::atomic<std::uint64_t> bytes_up_{0};
  std::atomic<std::uint64_t> bytes_down_{0};
  std::atomic<std::uint64_t> connections_total_{0};
  std::atomic<std::uint64_t> connect_failures_{0};
  std::atomic<std::uint64_t> lost_segments_{0};
};

}  // namespace edgeslam
