#pragma once
// The maps an edge server's sessions are writing now, by name. A client naming a map another
// client is writing joins it (one map, one back end, a window and slices of its own); the map
// lives while one of its clients' sessions does, then its threads and its store writer stop.
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>

#include "server/edge_map_session.h"
#include "store/map_store_writer.h"
#include "util/mutex.h"
#include "wire/wire_types.h"

namespace edgeslam {

struct LiveEdgeMap {
  LiveEdgeMap() = default;
  LiveEdgeMap(const LiveEdgeMap&) = delete;
  LiveEdgeMap& operator=(const LiveEdgeMap&) = delete;
  // The mapping threads stop before the writer that observes them.
  ~LiveEdgeMap();

  SessionConfig made_by;  // the first client's: its camera, sensor and settings hold for all
  std::unique_ptr<MapStoreWriter> store_writer;
  std::unique_ptr<EdgeMapSession> session;
};

// Why a client with `joining` cannot write into a map made by `made_by` (nullopt: it can). The
// map has one camera model, one sensor and one kind of features; semantic culling is the map's.
std::optional<std::string> whyCannotJoin(const SessionConfig& made_by,
                                         const SessionConfig& joining);

class LiveEdgeMaps {
 public:
  // The live map named `name` (joined = true), or the one `make` makes, now registered under that
  // name (joined = false). `make` runs under the directory's lock: two clients naming a new map at
  // once get one map. Exceptions from `make` propagate and register nothing.
  std::shared_ptr<LiveEdgeMap> findOrMake(const std::string& name,
                                          const std::function<std::shared_ptr<LiveEdgeMap>()>& make,
                                          bool& joined);

 private:
  Mutex mutex_;
  std::map<std::string, std::weak_ptr<LiveEdgeMap>> maps_ GUARDED_BY(mutex_);
};

}  // namespace edgeslam
