#include "store/store_schema.h"

#include <iterator>
#include <string>

#include "store/store_error.h"

namespace edgeslam {
namespace {

int pragmaInt(SqliteDatabase& db, const char* pragma) {
  SqliteStatement statement(db, std::string("PRAGMA ") + pragma);
  return statement.step() ? static_cast<int>(statement.columnInt(0)) : 0;
}

void createKeyFramePlaces(SqliteDatabase& db) {
  db.execute(R"sql(
CREATE TABLE keyframe_places(
  session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  keyframe INTEGER NOT NULL,
  vocabulary INTEGER NOT NULL,
  direct_index_depth INTEGER NOT NULL,
  bow BLOB NOT NULL,
  direct_index BLOB NOT NULL,
  PRIMARY KEY(session_id, keyframe)) WITHOUT ROWID;
)sql");
}

void createRoutes(SqliteDatabase& db) {
  db.execute(R"sql(
CREATE TABLE routes(
  map_id INTEGER NOT NULL REFERENCES maps(id) ON DELETE CASCADE,
  name TEXT NOT NULL,
  source TEXT NOT NULL,
  spacing_m REAL NOT NULL,
  up_x REAL NOT NULL, up_y REAL NOT NULL, up_z REAL NOT NULL,
  checkpoints BLOB NOT NULL,
  created REAL NOT NULL,
  PRIMARY KEY(map_id, name)) WITHOUT ROWID;
)sql");
}

void createTables(SqliteDatabase& db) {
  db.execute(R"sql(
CREATE TABLE maps(
  id INTEGER PRIMARY KEY,
  name TEXT NOT NULL UNIQUE,
  created REAL NOT NULL,
  updated REAL NOT NULL);
CREATE TABLE sessions(
  id INTEGER PRIMARY KEY,
  map_id INTEGER NOT NULL REFERENCES maps(id) ON DELETE CASCADE,
  client TEXT NOT NULL,
  sensor TEXT NOT NULL,
  width INTEGER NOT NULL, height INTEGER NOT NULL,
  fx REAL NOT NULL, fy REAL NOT NULL, cx REAL NOT NULL, cy REAL NOT NULL,
  k1 REAL NOT NULL, k2 REAL NOT NULL, p1 REAL NOT NULL, p2 REAL NOT NULL, k3 REAL NOT NULL,
  baseline_m REAL NOT NULL, depth_factor REAL NOT NULL, fps REAL NOT NULL,
  started REAL NOT NULL,
  ended REAL NOT NULL DEFAULT 0);
CREATE INDEX sessions_by_map ON sessions(map_id);
CREATE TABLE keyframes(
  session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  id INTEGER NOT NULL,
  frame_index INTEGER NOT NULL,
  timestamp REAL NOT NULL,
  pose BLOB NOT NULL,
  parent INTEGER NOT NULL,
  pyramid_levels INTEGER NOT NULL,
  scale_factor REAL NOT NULL,
  bf REAL NOT NULL,
  keypoints BLOB NOT NULL,
  descriptors BLOB NOT NULL,
  depth BLOB NOT NULL,
  right_u BLOB NOT NULL,
  PRIMARY KEY(session_id, id)) WITHOUT ROWID;
CREATE TABLE points(
  session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  id INTEGER NOT NULL,
  x REAL NOT NULL, y REAL NOT NULL, z REAL NOT NULL,
  nx REAL NOT NULL, ny REAL NOT NULL, nz REAL NOT NULL,
  descriptor BLOB NOT NULL,
  min_distance REAL NOT NULL,
  max_distance REAL NOT NULL,
  reference INTEGER NOT NULL,
  observations BLOB NOT NULL,
  PRIMARY KEY(session_id, id)) WITHOUT ROWID;
CREATE TABLE masks(
  session_id INTEGER NOT NULL REFERENCES sessions(id) ON DELETE CASCADE,
  keyframe INTEGER NOT NULL,
  width INTEGER NOT NULL,
  height INTEGER NOT NULL,
  encoding TEXT NOT NULL,
  bytes BLOB NOT NULL,
  PRIMARY KEY(session_id, keyframe)) WITHOUT ROWID;
)sql");
  createKeyFramePlaces(db);
  createRoutes(db);
}

// Migrations from version v to v + 1, in order; index 0 upgrades version 1. Version 1 -> 2 adds
// the keyframes' places (empty: keyframes stored before are described when they are loaded);
// 2 -> 3 adds the routes table (empty).
using Migration = void (*)(SqliteDatabase&);
constexpr Migration kMigrations[] = {createKeyFramePlaces, createRoutes};
static_assert(std::size(kMigrations) == kSchemaVersion - 1);

int tableCount(SqliteDatabase& db) {
  SqliteStatement count(db, "SELECT count(*) FROM sqlite_master");
  return count.step() ? static_cast<int>(count.columnInt(0)) : 0;
}

}  // namespace

int schemaVersion(SqliteDatabase& db) {
  return pragmaInt(db, "user_version");
}

void checkSchema(SqliteDatabase& db, bool writable) {
  const std::string file = db.file().string();
  // The first read of a file that is not SQLite (or whose header is damaged) fails here.
  const int application_id = pragmaInt(db, "application_id");
  const int version = pragmaInt(db, "user_version");
  if (tableCount(db) == 0 && version == 0) {
    if (!writable) throw StoreError(file + ": the map store is empty (no schema)");
    return;
  }
  if (application_id != kStoreApplicationId) {
    throw StoreError(file + ": not an edgeslam map store (a SQLite file of something else)");
  }
  if (version > kSchemaVersion) {
    throw StoreError(file + ": map store schema version " + std::to_string(version) +
                     " is newer than this edgeslam's (" + std::to_string(kSchemaVersion) +
                     "): use a newer edgeslam");
  }
  if (version < 1) {
    throw StoreError(file + ": map store schema version " + std::to_string(version) +
                     " is unknown");
  }
  if (version < kOldestReadableSchemaVersion && !writable) {
    throw StoreError(file + ": map store schema version " + std::to_string(version) +
                     " needs migrating: open it once with `edgeslam server --maps`");
  }
}

void prepareSchema(SqliteDatabase& db) {
  const int version = pragmaInt(db, "user_version");
  if (tableCount(db) == 0 && version == 0) {
    SqliteTransaction transaction(db);
    createTables(db);
    db.execute("PRAGMA application_id = " + std::to_string(kStoreApplicationId));
    db.execute("PRAGMA user_version = " + std::to_string(kSchemaVersion));
    transaction.commit();
    return;
  }
  if (version < kSchemaVersion) {
    SqliteTransaction transaction(db);
    for (int v = version; v < kSchemaVersion; ++v) kMigrations[v - 1](db);
    db.execute("PRAGMA user_version = " + std::to_string(kSchemaVersion));
    transaction.commit();
  }
}

}  // namespace edgeslam
