#pragma once
// The edge server's live sessions: id and id-origin allocation, lookup, idle clean-up.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "util/mutex.h"
#include "wire/edge_server.h"
#include "wire/slice_queue.h"

namespace edgeslam {

// A token bucket: at most `per_second` events a second, with a burst of as many.
struct UploadRate {
  // False when the event is over the rate (and is not counted).
  bool admit(double per_second, std::chrono::steady_clock::time_point now);

  double tokens = -1.0;  // < 0: not started (a full bucket)
  std::chrono::steady_clock::time_point last{};
};

// One session's state on the server. Destruction order matters: the backend (which holds the
// sink) goes before the slice queue.
struct ServerSession {
  ServerSession(SessionConfig session_config, SliceQueueLimits slice_limits)
      : config(std::move(session_config)), slices(slice_limits) {}
  ~ServerSession() { backend.reset(); }

  void touch() {
    last_activity_ns.store(std::chrono::steady_clock::now().time_since_epoch().count());
  }

  const SessionConfig config;
  std::string owner;  // the client's token label ("" without tokens); set before it is shared
  SliceQueue slices;
  Mutex backend_mutex;  // serialises calls into the backend
  std::unique_ptr<EdgeSessionBackend> backend;
  std::uint64_t last_upload_sequence GUARDED_BY(backend_mutex) = 0;

  std::atomic<std::int64_t> last_activity_ns{0};
  std::atomic<int> active_streams{0};
  std::atomic<std::uint64_t> uplink_bytes{0};
  std::atomic<std::uint64_t> downlink_bytes{0};
  std::atomic<std::uint64_t> keyframes{0};
  std::atomic<std::uint64_t> duplicate_uploads{0};
  std::atomic<std::uint64_t> missing_uploads{0};
  std::atomic<std::uint64_t> frames{0};
  std::atomic<std::uint64_t> slices_sent{0};
  UploadRate upload_rate GUARDED_BY(backend_mutex);
};

class SessionRegistryFull : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Who opens a session, and how many that client may hold (0: no limit).
struct SessionOwner {
  std::string name;
  std::size_t max_sessions = 0;
};

class SessionRegistry {
 public:
  // `reclaim_idle_after` > 0: when full, the session idle longest (at least that long, no open
  // slice stream) is closed to make room for a new one.
  explicit SessionRegistry(std::size_t max_sessions, SliceQueueLimits slice_limits,
                           std::chrono::milliseconds reclaim_idle_after = {});

  // Picks a session id and an id origin (the preferred one when free), then asks the factory for
  // a backend (without holding the registry lock: opening may be slow). Throws
  // SessionRegistryFull (the server or the owner at its limit), or whatever the factory throws.
  std::shared_ptr<ServerSession> open(SessionConfig config, EdgeSessionFactory& factory,
                                      const SessionOwner& owner = {});
  std::shared_ptr<ServerSession> find(std::uint64_t session_id) const;
  // Removes the session and closes its slice queue; false when unknown.
  bool close(std::uint64_t session_id) { return close(session_id, CloseReason::kByClient); }
  // Ends a session whose back end failed (EdgeSessionBackend::failure()); false when unknown.
  bool closeFailed(std::uint64_t session_id) { return close(session_id, CloseReason::kFailed); }
  // Closes sessions without an open stream whose last activity is older than `idle_timeout`.
  std::size_t closeIdle(std::chrono::milliseconds idle_timeout);
  void closeAll();

  std::vector<SessionStats> stats(bool costs = false) const;
  std::size_t size() const;
  std::uint64_t idleClosed() const { return idle_closed_.load(); }
  std::uint64_t reclaimed() const { return reclaimed_.load(); }
  ClosedSessionTotals closedTotals() const;

 private:
  enum class CloseReason { kByClient, kIdle, kReclaimed, kShutdown, kFailed };
  bool close(std::uint64_t session_id, CloseReason reason);
  // Adds a closed session to the totals and logs what it leaves undelivered.
  void account(const ServerSession& session, CloseReason reason);
  static SessionStats statsOf(const ServerSession& session, bool costs);
  std::uint8_t reserveOriginLocked(std::uint8_t preferred) REQUIRES(mutex_);
  // The session to close for a new one when full, or 0.
  std::uint64_t reclaimableLocked() const REQUIRES(mutex_);
  // Takes the session out (the caller closes its slices, outside the lock).
  std::shared_ptr<ServerSession> removeLocked(std::uint64_t session_id) REQUIRES(mutex_);
  void releaseOwnerLocked(const std::string& owner) REQUIRES(mutex_);

  const std::size_t max_sessions_;
  const SliceQueueLimits slice_limits_;
  const std::chrono::milliseconds reclaim_idle_after_;
  mutable Mutex mutex_;
  std::map<std::uint64_t, std::shared_ptr<ServerSession>> sessions_ GUARDED_BY(mutex_);
  std::vector<bool> origin_in_use_ GUARDED_BY(mutex_) = std::vector<bool>(256, false);
  std::size_t reserved_ GUARDED_BY(mutex_) = 0;  // origins taken, including those being opened
  std::uint8_t next_origin_ GUARDED_BY(mutex_) = 1;
  std::mt19937_64 random_ GUARDED_BY(mutex_){std::random_device{}()};
  std::atomic<std::uint64_t> idle_closed_{0};
  std::atomic<std::uint64_t> reclaimed_{0};
  // Open or being opened, per owner.
  std::map<std::string, std::size_t> owner_sessions_ GUARDED_BY(mutex_);
  mutable Mutex totals_mutex_;
  ClosedSessionTotals closed_totals_ GUARDED_BY(totals_mutex_);
};

}  // namespace edgeslam
