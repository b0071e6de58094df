#include "viz/edge_view.h"

#include <fmt/chrono.h>
#include <fmt/format.h>

#include <algorithm>
#include <nlohmann/json.hpp>
#include <utility>

#include "viz/edge_map_json.h"
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

nlohmann::json summaryJson(const MapSummary& m) {
  return {{"keyframes", m.keyframes}, {"points", m.points},   {"sessions", m.sessions},
          {"bytes", m.bytes},         {"created", m.created}, {"updated", m.updated}};
}

// A session's map as the view groups them: the sessions writing one named map share it; a
// localising session has a copy of its own, and so has a session without a name.
struct LiveMap {
  std::string key;
  std::string name;
  bool localize_only = false;
  std::shared_ptr<SlamSessionBackend> backend;  // one of its sessions', to sample it
  std::vector<std::uint64_t> sessions;
};

std::string mapKey(const SlamSessionBackend::MapIdentity& identity, std::uint64_t session_id) {
  if (!identity.name.empty() && !identity.localize_only) return identity.name;
  return identity.name.empty()
             ? fmt::format("session {}", session_id)
             : fmt::format("{} (localising, session {})", identity.name, session_id);
}

std::string loopEventText(const std::string& map, const LoopEvent& loop) {
  if (loop.keyframes_merged > 0) {
    return fmt::format(
        "maps merged in '{}': {} keyframes moved onto the other part (frames {} and {})", map,
        loop.keyframes_merged, loop.current_frame, loop.loop_frame);
  }
  return fmt::format("loop closed in '{}' (frames {} and {})", map, loop.current_frame,
                     loop.loop_frame);
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

void EdgeView::setStore(std::shared_ptr<MapStore> store) {
  MutexLock lock(mutex_);
  store_ = std::move(store);
  store_listed_at_.reset();
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

void EdgeView::refreshStoreListIfDue() {
  if (!store_) return;
  const auto now = std::chrono::steady_clock::now();
  if (store_listed_at_ && now - *store_listed_at_ < options_.store_refresh) return;
  store_listed_at_ = now;
  try {
    stored_maps_ = store_->listMaps();
    routes_.clear();
    for (const MapSummary& m : stored_maps_) routes_[m.name] = store_->listRoutes(m.name);
  } catch (const std::exception& e) {
    // A store the viewer cannot read shows no stored maps; the sessions go on.
    directory_->addEvent(fmt::format("the map store cannot be listed: {}", e.what()));
    stored_maps_.clear();
    routes_.clear();
  }
}

std::string EdgeView::buildJson() {
  refreshStoreListIfDue();
  const std::vector<SessionDirectory::Entry> entries = directory_->sessions();
  const std::vector<SessionStats> stats = stats_ ? stats_() : std::vector<SessionStats>{};

  // The live maps, each with the sessions in it.
  std::vector<LiveMap> live;
  std::map<std::uint64_t, std::pair<std::size_t, std::uint8_t>> map_of_session;  // index, origin
  for (const SessionDirectory::Entry& entry : entries) {
    const std::shared_ptr<SlamSessionBackend> backend = entry.backend.lock();
    if (!backend) continue;
    const SlamSessionBackend::MapIdentity identity = backend->mapIdentity();
    if (identity.map == nullptr) continue;  // nothing mapped yet
    const std::string key = mapKey(identity, entry.session_id);
    auto it =
        std::find_if(live.begin(), live.end(), [&](const LiveMap& m) { return m.key == key; });
    if (it == live.end()) {
      live.push_back({key, identity.name, identity.localize_only, backend, {}});
      it = std::prev(live.end());
    }
    it->sessions.push_back(entry.session_id);
    map_of_session[entry.session_id] = {static_cast<std::size_t>(it - live.begin()),
                                        backend->clientIdOrigin()};
  }

  const std::size_t points_each = options_.max_points / std::max<std::size_t>(1, live.size());
  nlohmann::json maps = nlohmann::json::array();
  std::vector<MapSample> samples;
  std::map<std::string, std::size_t> loops_now;
  for (const LiveMap& m : live) {
    EdgeMapContent content{.sample = m.backend->mapSample(points_each),
                           .loops = m.backend->loopEvents(),
                           .routes = {}};
    if (const auto r = routes_.find(m.name); r != routes_.end()) content.routes = r->second;
    std::size_t& seen = loops_seen_[m.key];
    if (content.loops.size() < seen) seen = 0;  // a map of that name started again
    for (std::size_t i = seen; i < content.loops.size(); ++i) {
      directory_->addEvent(loopEventText(m.key, content.loops[i]));
      ++loops_total_;
      if (content.loops[i].keyframes_merged > 0) ++merges_total_;
    }
    seen = content.loops.size();
    loops_now[m.key] = seen;

    nlohmann::json map = edgeMapJson(content, options_.max_keyframes);
    map["name"] = m.key;
    map["live"] = true;
    map["localize_only"] = m.localize_only;
    nlohmann::json ids = nlohmann::json::array();
    for (std::uint64_t id : m.sessions) ids.push_back(std::to_string(id));
    map["sessions"] = std::move(ids);
    map["stored"] = nullptr;
    for (const MapSummary& s : stored_maps_) {
      if (s.name == m.name && !m.localize_only) map["stored"] = summaryJson(s);
    }
    maps.push_back(std::move(map));
    samples.push_back(std::move(content.sample));
  }
  std::erase_if(loops_seen_, [&](const auto& kv) { return !loops_now.contains(kv.first); });
  for (const MapSummary& s : stored_maps_) {
    const bool is_live = std::any_of(live.begin(), live.end(), [&](const LiveMap& m) {
      return m.name == s.name && !m.localize_only;
    });
    if (is_live) continue;
    maps.push_back({{"name", s.name},
                    {"live", false},
                    {"localize_only", false},
                    {"sessions", nlohmann::json::array()},
                    {"keyframe_count", s.keyframes},
                    {"map_points", s.points},
                    {"stored", summaryJson(s)}});
  }

  nlohmann::json sessions = nlohmann::json::array();
  for (const SessionDirectory::Entry& entry : entries) {
    std::optional<SessionStats> session_stats;
    for (const SessionStats& s : stats) {
      if (s.session_id == entry.session_id) session_stats = s;
    }
    nlohmann::json session = statsJson(session_stats);
    // As text: session ids use all 64 bits, more than a JavaScript number holds exactly.
    session["session_id"] = std::to_string(entry.session_id);
    session["client_name"] = entry.client_name;
    session["sensor"] = entry.sensor;
    session["map"] = nullptr;
    session["camera"] = nullptr;
    session["keyframe_count"] = 0;
    if (const auto found = map_of_session.find(entry.session_id); found != map_of_session.end()) {
      const auto [index, origin] = found->second;
      const MapSample& sample = samples[index];
      session["map"] = live[index].key;
      session["origin"] = origin;
      session["keyframe_count"] =
          std::count_if(sample.keyframe_ids.begin(), sample.keyframe_ids.end(),
                        [origin = origin](KeyFrameId id) { return idOrigin(id) == origin; });
      if (const std::optional<SE3d> newest = newestKeyFrameOf(sample, origin)) {
        if (auto pose = poseJson({newest->translation(), newest->rotation()})) {
          session["camera"] = std::move(*pose);
        }
      }
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
                               {"maps", maps.size()},
                               {"loops", loops_total_},
                               {"merges", merges_total_}}},
                             {"maps", std::move(maps)},
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

std::optional<std::string> EdgeView::storedMapJson(const std::string& name) {
  std::shared_ptr<MapStore> store;
  {
    MutexLock lock(mutex_);
    store = store_;
  }
  if (!store) return std::nullopt;
  const std::optional<MapSummary> summary = store->mapInfo(name);
  if (!summary) return std::nullopt;
  MutexLock lock(stored_mutex_);
  if (const auto cached = stored_cache_.find(name);
      cached != stored_cache_.end() && cached->second.updated == summary->updated) {
    return cached->second.json;
  }
  std::optional<StoredMap> stored = store->loadMap(name);
  if (!stored) return std::nullopt;
  EdgeMapContent content{.sample = sampleOfStoredMap(*stored, options_.max_points),
                         .loops = {},
                         .routes = store->listRoutes(name)};
  nlohmann::json map = edgeMapJson(content, options_.max_keyframes);
  map["name"] = name;
  map["live"] = false;
  map["localize_only"] = false;
  map["sessions"] = nlohmann::json::array();
  map["stored"] = summaryJson(*summary);
  std::string json = map.dump();
  if (stored_cache_.size() >= kStoredMapsCached) stored_cache_.erase(stored_cache_.begin());
  stored_cache_[name] = {summary->updated, json};
  return json;
}

}  // namespace edgeslam::viz
