#pragma once
// The edge view (`server --viewer`): every map the edge server holds (the maps its sessions write
// or localise in now, and the maps of its store), for each live map its points, keyframes, one
// trajectory per client, its loops and merges; each session's figures and live position; sessions
// joining and leaving, loops closed and maps merged as events. The maps are sampled by the viewer's
// threads, at most once per `refresh` and only while a page asks; the server's threads never wait
// for a viewer beyond the map's update mutex (and, for a stored map a page opens, the store's).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "store/map_store.h"
#include "util/mutex.h"
#include "viz/view_source.h"
#include "viz/viewed_session_factory.h"
#include "wire/edge_server.h"

namespace edgeslam::viz {

struct EdgeViewOptions {
  std::size_t max_points = 20000;    // over all live maps; and for a stored map
  std::size_t max_keyframes = 2000;  // per map
  std::chrono::milliseconds refresh{500};
  std::chrono::milliseconds store_refresh{5000};  // the store's list of maps and routes
};

class EdgeView : public ViewSource {
 public:
  using StatsSource = std::function<std::vector<SessionStats>()>;

  explicit EdgeView(std::shared_ptr<SessionDirectory> directory, EdgeViewOptions options = {});
  // The server's per-session figures (EdgeServer::sessions); cleared before the server goes.
  void setStatsSource(StatsSource source);
  void clearStatsSource();
  // The server's map store: its maps are listed, and shown when a page asks (storedMapJson).
  void setStore(std::shared_ptr<MapStore> store);

  std::string snapshotJson() override;
  // A map of the store as one "maps" entry; nullopt when there is no store or no such map.
  std::optional<std::string> storedMapJson(const std::string& name) override;

 private:
  std::string buildJson() REQUIRES(mutex_);
  void refreshStoreListIfDue() REQUIRES(mutex_);

  std::shared_ptr<SessionDirectory> directory_;
  EdgeViewOptions options_;
  Mutex mutex_;
  StatsSource stats_ GUARDED_BY(mutex_);
  std::shared_ptr<MapStore> store_ GUARDED_BY(mutex_);
  std::vector<MapSummary> stored_maps_ GUARDED_BY(mutex_);
  std::map<std::string, std::vector<RouteRecord>> routes_ GUARDED_BY(mutex_);  // by map
  std::optional<std::chrono::steady_clock::time_point> store_listed_at_ GUARDED_BY(mutex_);
  std::uint64_t version_ GUARDED_BY(mutex_) = 0;
  // Loops seen in each live map (by the map's key), to tell the new ones as events.
  std::map<std::string, std::size_t> loops_seen_ GUARDED_BY(mutex_);
  std::size_t loops_total_ GUARDED_BY(mutex_) = 0;
  std::size_t merges_total_ GUARDED_BY(mutex_) = 0;
  std::optional<std::chrono::steady_clock::time_point> built_at_ GUARDED_BY(mutex_);
  std::string encoded_ GUARDED_BY(mutex_);
  std::string last_body_ GUARDED_BY(mutex_);

  // A stored map's encoding, kept while the map is not updated (loading one takes ~1 s for 1000
  // keyframes). Its own mutex: a page opening a stored map does not hold up the live snapshot.
  Mutex stored_mutex_;
  struct StoredEncoding {
    double updated = 0.0;
    std::string json;
  };
  std::map<std::string, StoredEncoding> stored_cache_ GUARDED_BY(stored_mutex_);
  static constexpr std::size_t kStoredMapsCached = 8;
};

}  // namespace edgeslam::viz
