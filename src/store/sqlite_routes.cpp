// The routes table of the SQLite store (schema version 3): one row per route of a map.
#include <sqlite3.h>

#include <chrono>
#include <cstring>

#include "store/sqlite_map_store.h"
#include "store/store_error.h"

namespace edgeslam {
namespace {

std::vector<std::uint8_t> checkpointsBlob(const std::vector<Eigen::Vector3d>& checkpoints) {
  std::vector<std::uint8_t> bytes(checkpoints.size() * 3 * sizeof(double));
  for (std::size_t i = 0; i < checkpoints.size(); ++i) {
    std::memcpy(bytes.data() + i * 3 * sizeof(double), checkpoints[i].data(), 3 * sizeof(double));
  }
  return bytes;
}

std::vector<Eigen::Vector3d> checkpointsFromBlob(std::span<const std::uint8_t> bytes,
                                                 const std::string& file) {
  constexpr std::size_t kStride = 3 * sizeof(double);
  if (bytes.size() % kStride != 0) {
    throw StoreError(file + ": a route's checkpoints are damaged (" + std::to_string(bytes.size()) +
                     " bytes)");
  }
  std::vector<Eigen::Vector3d> out(bytes.size() / kStride);
  for (std::size_t i = 0; i < out.size(); ++i) {
    std::memcpy(out[i].data(), bytes.data() + i * kStride, kStride);
  }
  return out;
}

double unixSeconds() {
  return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch()).count();
}

bool hasRoutesTable(SqliteDatabase& db) {
  SqliteStatement s(db, "SELECT count(*) FROM sqlite_master WHERE type = 'table' AND name = ?");
  s.bind(1, std::string("routes"));
  return s.step() && s.columnInt(0) > 0;
}

}  // namespace

void SqliteMapStore::saveRoute(const std::string& map, const RouteRecord& route) {
  MutexLock lock(mutex_);
  const auto id = mapId(map);
  if (!id) throw StoreError(location() + ": no map named '" + map + "'");
  SqliteTransaction transaction(db_);
  SqliteStatement s(db_,
                    "INSERT OR REPLACE INTO routes(map_id, name, source, spacing_m, up_x, up_y, "
                    "up_z, checkpoints, created) VALUES(?, ?, ?, ?, ?, ?, ?, ?, ?)");
  const std::vector<std::uint8_t> blob = checkpointsBlob(route.checkpoints);
  s.bind(1, *id)
      .bind(2, route.name)
      .bind(3, route.source)
      .bind(4, route.spacing_m)
      .bind(5, route.up.x())
      .bind(6, route.up.y())
      .bind(7, route.up.z())
      .bindBlob(8, blob)
      .bind(9, route.created > 0.0 ? route.created : unixSeconds())
      .run();
  transaction.commit();
}

std::vector<RouteRecord> SqliteMapStore::listRoutes(const std::string& map) {
  MutexLock lock(mutex_);
  std::vector<RouteRecord> out;
  const auto id = mapId(map);
  // A store of an older schema, opened to read only, has no routes yet.
  if (!id || !hasRoutesTable(db_)) return out;
  SqliteStatement s(db_,
                    "SELECT name, source, spacing_m, up_x, up_y, up_z, checkpoints, created "
                    "FROM routes WHERE map_id = ? ORDER BY name");
  s.bind(1, *id);
  while (s.step()) {
    RouteRecord route;
    route.name = s.columnText(0);
    route.source = s.columnText(1);
    route.spacing_m = s.columnDouble(2);
    route.up = Eigen::Vector3d(s.columnDouble(3), s.columnDouble(4), s.columnDouble(5));
    route.checkpoints = checkpointsFromBlob(s.columnBlobView(6), location());
    route.created = s.columnDouble(7);
    out.push_back(std::move(route));
  }
  return out;
}

bool SqliteMapStore::removeRoute(const std::string& map, const std::string& route) {
  MutexLock lock(mutex_);
  const auto id = mapId(map);
  if (!id || !hasRoutesTable(db_)) return false;
  SqliteTransaction transaction(db_);
  SqliteStatement s(db_, "DELETE FROM routes WHERE map_id = ? AND name = ?");
  s.bind(1, *id).bind(2, route).run();
  const bool removed = sqlite3_changes(db_.handle()) > 0;
  transaction.commit();
  return removed;
}

}  // namespace edgeslam
