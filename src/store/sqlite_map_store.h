#pragma once
// The embedded map store: one SQLite database in WAL mode (a killed process never leaves a store
// that does not open; each batch is one transaction). Thread-safe: calls are serialised by one
// mutex, so the writers of several sessions share the store.
#include <filesystem>
#include <memory>
#include <unordered_map>

#include "store/map_store.h"
#include "store/sqlite_database.h"
#include "util/mutex.h"

namespace edgeslam {

class SqliteMapStore : public MapStore {
 public:
  // `lock_fd`: the held lock file of a writing process (closed with the store), or -1.
  SqliteMapStore(const std::filesystem::path& file, MapStoreAccess access, int lock_fd);
  ~SqliteMapStore() override;

  std::string location() const override { return file_.string(); }
  std::vector<MapSummary> listMaps() override;
  std::optional<MapSummary> mapInfo(const std::string& name) override;
  std::optional<StoredMap> loadMap(const std::string& name) override;
  StoreSessionId beginSession(const std::string& map, const StoredSessionInfo& info) override;
  void write(StoreSessionId session, const MapStoreBatch& batch) override;
  void endSession(StoreSessionId session) override;
  void resumeSession(StoreSessionId session) override;
  bool removeMap(const std::string& name) override;
  // In sqlite_routes.cpp.
  void saveRoute(const std::string& map, const RouteRecord& route) override;
  std::vector<RouteRecord> listRoutes(const std::string& map) override;
  bool removeRoute(const std::string& map, const std::string& route) override;

 private:
  struct Statements;
  struct PlaceStatements;
  std::optional<std::int64_t> mapId(const std::string& name) REQUIRES(mutex_);
  MapSummary summary(std::int64_t map_id, const std::string& name) REQUIRES(mutex_);
  StoredSession loadSession(SqliteStatement& row) REQUIRES(mutex_);
  void loadPlaces(StoredSession& session,
                  const std::unordered_map<KeyFrameId, std::size_t>& keyframe_index)
      REQUIRES(mutex_);

  Mutex mutex_;
  const std::filesystem::path file_;
  int lock_fd_;
  SqliteDatabase db_ GUARDED_BY(mutex_);
  std::unique_ptr<Statements> statements_ GUARDED_BY(mutex_);
  // nullptr in a version 1 store (read).
  std::unique_ptr<PlaceStatements> place_statements_ GUARDED_BY(mutex_);
};

}  // namespace edgeslam
