#include "net/session_registry.h"

#include <fmt/format.h>

#include <algorithm>

namespace edgeslam {

SessionRegistry::SessionRegistry(std::size_t max_sessions, SliceQueueLimits slice_limits)
    : max_sessions_(std::clamp<std::size_t>(max_sessions, 1, 255)), slice_limits_(slice_limits) {}

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
                                                     EdgeSessionFactory& factory) {
  {
    std::lock_guard lock(mutex_);
    config.id_origin = reserveOriginLocked(config.id_origin);
    do {
      config.session_id = random_();
    } while (config.session_id == 0 || sessions_.count(config.session_id) != 0);
  }
  auto session = std::make_shared<ServerSession>(std::move(config), slice_limits_);
  try {
    session->backend = factory.open(session->config, session->slices);
    if (!session->backend) throw std::runtime_error("the session factory returned no backend");
  } catch (...) {
    std::lock_guard lock(mutex_);
    origin_in_use_[session->config.id_origin] = false;
    --reserved_;
    throw;
  }
  session->touch();
  std::lock_guard lock(mutex_);
  sessions_.emplace(session->config.session_id, session);
  return session;
}

std::shared_ptr<ServerSession> SessionRegistry::find(std::uint64_t session_id) const {
  std::lock_guard lock(mutex_);
  const auto it = sessions_.find(session_id);
  return it == sessions_.end() ? nullptr : it->second;
}

bool SessionRegistry::close(std::uint64_t session_id, bool idle) {
  std::shared_ptr<ServerSession> session;
  {
    std::lock_guard lock(mutex_);
    const auto it = sessions_.find(session_id);
    if (it == sessions_.end()) return false;
    session = std::move(it->second);
    sessions_.erase(it);
    origin_in_use_[session->config.id_origin] = false;
    --reserved_;
    if (idle) ++idle_closed_;  // counted before the backend can go, for whoever watches it go
  }
  session->slices.close();
  return true;  // the backend goes when the last RPC using the session lets go
}

std::size_t SessionRegistry::closeIdle(std::chrono::milliseconds idle_timeout) {
  const std::int64_t now = std::chrono::steady_clock::now().time_since_epoch().count();
  const std::int64_t limit = std::chrono::nanoseconds(idle_timeout).count();
  std::vector<std::uint64_t> idle;
  {
    std::lock_guard lock(mutex_);
    for (const auto& [id, session] : sessions_) {
      if (session->active_streams.load() == 0 && now - session->last_activity_ns.load() > limit) {
        idle.push_back(id);
      }
    }
  }
  std::size_t closed = 0;
  for (const std::uint64_t id : idle) closed += close(id, true) ? 1 : 0;
  return closed;
}

void SessionRegistry::closeAll() {
  std::vector<std::uint64_t> ids;
  {
    std::lock_guard lock(mutex_);
    for (const auto& entry : sessions_) ids.push_back(entry.first);
  }
  for (const std::uint64_t id : ids) close(id);
}

std::vector<SessionStats> SessionRegistry::stats() const {
  std::vector<std::shared_ptr<ServerSession>> sessions;
  {
    std::lock_guard lock(mutex_);
    for (const auto& entry : sessions_) sessions.push_back(entry.second);
  }
  std::vector<SessionStats> out;
  for (const auto& s : sessions) {
    SessionStats stats;
    stats.session_id = s->config.session_id;
    stats.id_origin = s->config.id_origin;
    stats.client_name = s->config.client_name;
    stats.uplink_bytes = s->uplink_bytes.load();
    stats.downlink_bytes = s->downlink_bytes.load();
    stats.keyframes = s->keyframes.load();
    stats.duplicate_uploads = s->duplicate_uploads.load();
    stats.frames = s->frames.load();
    stats.slices_pushed = s->slices.lastPushed();
    stats.slices_sent = s->slices_sent.load();
    stats.slices_dropped = s->slices.droppedUnacknowledged();
    stats.slices_acknowledged = s->slices.acknowledged();
    stats.streaming = s->active_streams.load() > 0;
    out.push_back(std::move(stats));
  }
  return out;
}

std::size_t SessionRegistry::size() const {
  std::lock_guard lock(mutex_);
  return sessions_.size();
}

}  // namespace edgeslam
