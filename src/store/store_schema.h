#pragma once
// The SQLite store's schema: created on a new store, migrated on an older one, and a store written
// by a newer edgeslam refused (before anything is written).
#include "store/sqlite_database.h"

namespace edgeslam {

// Version 1: maps, sessions (with their camera), keyframes (pose, features as blobs), points
// (position, appearance, observations as a blob), masks (semantic labels).
// Version 2: keyframe_places (each keyframe's bag of words and direct index, and the vocabulary
// that made them).
// Version 3: routes (a map's navigation routes: checkpoints in the map's frame).
constexpr int kSchemaVersion = 3;
// Readers (list, info, export) open stores of this version on without migrating them: what later
// versions added is optional to them.
constexpr int kOldestReadableSchemaVersion = 1;
// "ESLM": tells an edgeslam store from any other SQLite file.
constexpr int kStoreApplicationId = 0x45534c4d;

// Throws StoreError naming the file: not a store, damaged, or a newer version; writes nothing.
void checkSchema(SqliteDatabase& db, bool writable);
// After checkSchema: creates the schema of a new store or migrates an older one.
void prepareSchema(SqliteDatabase& db);
// The store's schema version (PRAGMA user_version).
int schemaVersion(SqliteDatabase& db);

}  // namespace edgeslam
