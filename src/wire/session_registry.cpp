#include "wire/session_registry.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>

namespace edgeslam {

bool UploadRate::admit(double per_second, std::chrono::steady_clock::time_point now) {
  if (per_second <= 0.0) return true;
  if (tokens < 0.0) {
    tokens = per_second;
  } else {
    const double elapsed_s = std::chrono::duration<double>(now - last).count();
    tokens = std::min(per_second, tokens + std::max(0.0, elapsed_s) * per_second);
  }
  last = now;
  if (tokens < 1.0) return false;
  tokens -= 1.0;
  return true;
}

SessionRegistry::SessionRegistry(std::size_t max_sessions, SliceQueueLimits slice_limits,
                                 std::chrono::milliseconds reclaim_idle_after)
    : max_sessions_(std::clamp<std::size_t>(max_sessions, 1, 255)),
      slice_limits_(slice_limits),
      reclaim_idle_after_(reclaim_idle_after) {}

std::uint64_t SessionRegistry::reclaimableLocked() const {
  if (reclaim_idle_after_.count() <= 0) return 0;
  const std::int64_t now = std::chrono::steady_clock::now().time_since_epoch().count();
  std::int64_t longest = std::chrono::nanoseconds(reclaim_idle_after_).count();
  std::uint64_t victim = 0;
  for (const auto& [id, session] : sessions_) {
    const std::int64_t idle = now - session->last_activity_ns.load();
    if (session->active_streams.load() == 0 && idle >= longest) {
      longest = idle;
      victim = id;
    }
  }
  return victim;
}

std::shared_ptr<ServerSession> SessionRegistry::removeLocked(std::uint64_t session_id) {
  const auto it = sessions_.find(session_id);
  if (it == sessions_.end()) return nullptr;
  std::shared_ptr<ServerSession> session = std::move(it->second);
  sessions_.erase(it);
  origin_in_use_[session->config.id_origin] = false;
  --reserved_;
  releaseOwnerLocked(session->owner);
  return session;
}

void SessionRegistry::releaseOwnerLocked(const std::string& owner) {
  const auto it = owner_sessions_.find(owner);
  if (it == owner_sessions_.end()) return;
  if (--it->second == 0) owner_sessions_.erase(it);
}

std::uint8_t SessionRegistry::reserveOriginLocked(std::uint8_t preferred) {
  if (reserved_ >= max_sessions_) {
    throw SessionRegistryFull(
        fmt::format("the server already holds its maximum of {} sessions", max_sessions_));
  }
  std::uint8_t origin = 0;
  if (preferred != 0 && !origin_in_use_[preferred]) {
    origin = preferred;
  } else {
    // Round robin, so a closed session's origin is not handed out again at once.
    for (int step = 0; step < 255 && origin == 0; ++step) {
      const std::uint8_t candidate = next_origin_;
      next_origin_ = next_origin_ == 255 ? 1 : static_cast<std::uint8_t>(next_origin_ + 1);
      if (!origin_in_use_[candidate]) origin = candidate;
    }
  }
  origin_in_use_[origin] = true;
  ++reserved_;
  return origin;
}

std::shared_ptr<ServerSession> SessionRegistry::open(SessionConfig config,
                                                     EdgeSessionFactory& factory,
                                                     const SessionOwner& owner) {
  std::shared_ptr<ServerSession> reclaimed;
  {
    MutexLock lock(mutex_);
    const auto owned = owner_sessions_.find(owner.name);
    if (owner.max_sessions > 0 && owned != owner_sessions_.end() &&
        owned->second >= owner.max_sessions) {
      throw SessionRegistryFull(fmt::format("{} already holds its maximum of {} sessions",
                                            owner.name, owner.max_sessions));
    }
    if (reserved_ >= max_sessions_) {
      if (const std::uint64_t victim = reclaimableLocked(); victim != 0) {
        reclaimed = removeLocked(victim);
        ++reclaimed_;
      }
    }
    config.id_origin = reserveOriginLocked(config.id_origin);
    ++owner_sessions_[owner.name];
    do {
      config.session_id = random_();
    } while (config.session_id == 0 || sessions_.count(config.session_id) != 0);
  }
  if (reclaimed) {
    spdlog::info("edge server: session {:#x} ('{}') closed, unused for {} ms, to make room",
                 reclaimed->config.session_id, reclaimed->config.client_name,
                 reclaim_idle_after_.count());
    account(*reclaimed, CloseReason::kReclaimed);
    reclaimed->slices.close();
    reclaimed.reset();
  }
  auto session = std::make_shared<ServerSession>(std::move(config), slice_limits_);
  session->owner = owner.name;
  try {
    session->backend = factory.open(session->config, session->slices);
    if (!session->backend) throw std::runtime_error("the session factory returned no backend");
  } catch (...) {
    MutexLock lock(mutex_);
    origin_in_use_[session->config.id_origin] = false;
    --reserved_;
    releaseOwnerLocked(session->owner);
    throw;
  }
  session->touch();
  MutexLock lock(mutex_);
  sessions_.emplace(session->config.session_id, session);
  return session;
}

std::shared_ptr<ServerSession> SessionRegistry::find(std::uint64_t session_id) const {
  MutexLock lock(mutex_);
  const auto it = sessions_.find(session_id);
  return it == sessions_.end() ? nullptr : it->second;
}

bool SessionRegistry::close(std::uint64_t session_id, CloseReason reason) {
  std::shared_ptr<ServerSession> session;
  {
    MutexLock lock(mutex_);
    session = removeLocked(session_id);
    if (session == nullptr) return false;
    // Counted before the backend can go, for whoever watches it go.
    if (reason == CloseReason::kIdle) ++idle_closed_;
  }
  account(*session, reason);
  session->slices.close();
  return true;  // the backend goes when the last RPC using the session lets go
}

std::size_t SessionRegistry::closeIdle(std::chrono::milliseconds idle_timeout) {
  const std::int64_t now = std::chrono::steady_clock::now().time_since_epoch().count();
  const std::int64_t limit = std::chrono::nanoseconds(idle_timeout).count();
  std::vector<std::uint64_t> idle;
  {
    MutexLock lock(mutex_);
    for (const auto& [id, session] : sessions_) {
      if (session->active_streams.load() == 0 && now - session->last_activity_ns.load() > limit) {
        idle.push_back(id);
      }
    }
  }
  std::size_t closed = 0;
  for (const std::uint64_t id : idle) closed += close(id, CloseReason::kIdle) ? 1 : 0;
  return closed;
}

void SessionRegistry::closeAll() {
  std::vector<std::uint64_t> ids;
  {
    MutexLock lock(mutex_);
    for (const auto& entry : sessions_) ids.push_back(entry.first);
  }
  for (const std::uint64_t id : ids) close(id, CloseReason::kShutdown);
}

void SessionRegistry::account(const ServerSession& s, CloseReason reason) {
  const std::uint64_t pushed = s.slices.lastPushed();
  const std::uint64_t acknowledged = s.slices.acknowledged();
  const std::uint64_t unacknowledged = pushed - std::min(pushed, acknowledged);
  const std::uint64_t dropped = s.slices.droppedUnacknowledged();
  SessionStats last = statsOf(s, true);
  {
    MutexLock lock(totals_mutex_);
    ClosedSessionTotals& t = closed_totals_;
    ++t.sessions;
    switch (reason) {
      case CloseReason::kByClient:
        ++t.closed_by_client;
        break;
      case CloseReason::kIdle:
        ++t.closed_idle;
        break;
      case CloseReason::kReclaimed:
        ++t.closed_reclaimed;
        break;
      case CloseReason::kShutdown:
        ++t.closed_at_shutdown;
        break;
      case CloseReason::kFailed:
        ++t.closed_failed;
        break;
    }
    t.keyframes += s.keyframes.load();
    t.duplicate_uploads += s.duplicate_uploads.load();
    t.missing_uploads += s.missing_uploads.load();
    t.slices_pushed += pushed;
    t.slices_dropped += dropped;
    t.slices_unacknowledged += unacknowledged;
    if (t.recent.size() == ClosedSessionTotals::kRecentClosedSessions)
      t.recent.erase(t.recent.begin());
    t.recent.push_back(std::move(last));
  }
  // The last slice of a clean end is applied but never acknowledged (acknowledgements ride on
  // uploads, and none follows it): not worth a warning.
  if (reason == CloseReason::kByClient && unacknowledged <= 1 && dropped == 0 &&
      s.missing_uploads.load() == 0) {
    return;  // EdgeService logs the close
  }
  static constexpr const char* kReasons[] = {"by its client", "idle (its client went silent)",
                                             "to make room", "at shutdown",
                                             "after its back end failed"};
  spdlog::warn(
      "edge server: session {:#x} ('{}') closed {}: {} keyframes received, {} uploads missing, "
      "{} duplicate; {} of {} slices never acknowledged ({} dropped unacknowledged)",
      s.config.session_id, s.config.client_name, kReasons[static_cast<int>(reason)],
      s.keyframes.load(), s.missing_uploads.load(), s.duplicate_uploads.load(), unacknowledged,
      pushed, dropped);
}

ClosedSessionTotals SessionRegistry::closedTotals() const {
  MutexLock lock(totals_mutex_);
  return closed_totals_;
}

SessionStats SessionRegistry::statsOf(const ServerSession& s, bool costs) {
  SessionStats stats;
  stats.session_id = s.config.session_id;
  stats.id_origin = s.config.id_origin;
  stats.client_name = s.config.client_name;
  stats.uplink_bytes = s.uplink_bytes.load();
  stats.downlink_bytes = s.downlink_bytes.load();
  stats.keyframes = s.keyframes.load();
  stats.duplicate_uploads = s.duplicate_uploads.load();
  stats.missing_uploads = s.missing_uploads.load();
  stats.frames = s.frames.load();
  stats.slices_pushed = s.slices.lastPushed();
  stats.slices_sent = s.slices_sent.load();
  stats.slices_dropped = s.slices.droppedUnacknowledged();
  stats.slices_acknowledged = s.slices.acknowledged();
  stats.streaming = s.active_streams.load() > 0;
  // Set once when the session opens, before it is shared; absent while it is being opened.
  if (costs && s.backend) stats.costs = s.backend->costs();
  return stats;
}

std::vector<SessionStats> SessionRegistry::stats(bool costs) const {
  std::vector<std::shared_ptr<ServerSession>> sessions;
  {
    MutexLock lock(mutex_);
    for (const auto& entry : sessions_) sessions.push_back(entry.second);
  }
  std::vector<SessionStats> out;
  out.reserve(sessions.size());
  for (const auto& s : sessions) out.push_back(statsOf(*s, costs));
  return out;
}

std::size_t SessionRegistry::size() const {
  MutexLock lock(mutex_);
  return sessions_.size();
}

}  // namespace edgeslam
