#include "viz/edge_view.h"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <utility>

#include "viz/view_snapshot.h"

namespace edgeslam::viz {
namespace {

nlohmann::json statsJson(const std::optional<SessionStats>& s) {
  if (!s) return {{"uplink_bytes", 0}, {"downlink_bytes", 0}, {"frames", 0}, {"uploads", 0}};
  return {{"uplink_bytes", s->uplink_bytes},
          {"downlink_bytes", s->downlink_bytes},
          {"frames", s->frames},
          {"uploads", s->keyframes},
          {"slices_sent", s->slices_sent},
          {"streaming", s->streaming}};
}

}  // namespace

EdgeView::EdgeView(std::shared_ptr<SessionDirectory> directory, EdgeViewOptions options)
    : directory_(std::move(directory)), options_(options) {}

void EdgeView::setStatsSource(StatsSource source) {
  MutexLock lock(mutex_);
  stats_ = std::move(source);
}

void EdgeView::clearStatsSource() {
  MutexLock lock(mutex_);
  stats_ = nullptr;
}

std::string EdgeView::snapshotJson() {
  MutexLock lock(mutex_);
  const auto now = std::chrono::steady_clock::now();
  if (!built_at_ || now - *built_at_ >= options_.refresh) {
    encoded_ = buildJson();
    built_at_ = now;
  }
  return encoded_;
}

std::string EdgeView::buildJson() {
  const std::vector<SessionDirectory::Entry> entries = directory_->sessions();
  const std::vector<SessionStats> stats = stats_ ? stats_() : std::vector<SessionStats>{};
  const std::size_t points_each = options_.max_points / std::max<std::size_t>(1, entries.size());
  nlohmann::json sessions = nlohmann::json::array();
  for (const SessionDirectory::Entry& entry : entries) {
    ViewSnapshot map;  // reuses the mobile view's encoding of positions and poses
    std::size_t loops = 0;
    if (const std::shared_ptr<SlamSessionBackend> backend = entry.backend.lock()) {
      MapSample sample = backend->mapSample(points_each);
      loops = backend->loops();
      const std::size_t n = sample.keyframe_poses.size();
      const std::size_t step =
          std::max<std::size_t>(1, (n + options_.max_keyframes - 1) / options_.max_keyframes);
      for (std::size_t i = 0; i < n; ++i) {
        const SE3d& pose = sample.keyframe_poses[i];
        map.trajectory.push_back(pose.translation());
        if ((n - 1 - i) % step == 0) map.keyframes.push_back({pose.translation(), pose.rotation()});
      }
      if (n > 0) {
        map.camera = ViewPose{sample.keyframe_poses.back().translation(),
                              sample.keyframe_poses.back().rotation()};
      }
      map.points = std::move(sample.points);
      map.points_total = sample.total_points;
      map.status.keyframes = n;
    }
    std::size_t& seen = loops_seen_[entry.session_id];
    if (loops > seen) {
      directory_->addEvent(fmt::format("loop closed in session {} '{}' ({} so far)",
                                       entry.session_id, entry.client_name, loops));
      loops_total_ += loops - seen;
      seen = loops;
    }
    std::optional<SessionStats> session_stats;
    for (const SessionStats& s : stats) {
      if (s.session_id == entry.session_id) session_stats = s;
    }
    nlohmann::json encoded = toJson(map);
    nlohmann::json session = statsJson(session_stats);
    // As text: session ids use all 64 bits, more than a JavaScript number holds exactly.
    session["session_id"] = std::to_string(entry.session_id);
    session["client_name"] = entry.client_name;
    session["sensor"] = entry.sensor;
    session["keyframe_count"] = map.status.keyframes;
    session["map_points"] = map.points_total;
    session["loops"] = loops;
    for (const char* key : {"camera", "trajectory", "keyframes", "points"}) {
      session[key] = std::move(encoded[key]);
    }
    sessions.push_back(std::move(session));
  }
  nlohmann::json events = nlohmann::json::array();
  for (const ViewerEvent& e : directory_->events()) {
    events.push_back(
        {{"time",
          fmt::format("{:%H:%M:%S}", fmt::gmtime(std::chrono::system_clock::to_time_t(e.time)))},
         {"text", e.text}});
  }
  nlohmann::json snapshot = {{"view", "edge"},
                             {"status",
                              {{"sessions", entries.size()},
                               {"sessions_opened", directory_->openedCount()},
                               {"loops", loops_total_}}},
                             {"sessions", std::move(sessions)},
                             {"events", std::move(events)}};
  // The version grows only when something changed, as the mobile view's does.
  std::string body = snapshot.dump();
  if (body != last_body_) {
    ++version_;
    last_body_ = std::move(body);
  }
  snapshot["version"] = version_;
  return snapshot.dump();
}

}  // namespace edgeslam::viz
