#pragma once
// The SQLite store's schema: created on a new store, migrated on an older one, and a store written
// by a newer edgeslam refused (before anything is written).
#include "store/sqlite_database.h"

namespace edgeslam {

// Version 1: maps, sessions (with their camera), keyframes (pose, features as blobs), points
// (position, appearance, observations as a blob), masks (semantic labels).
constexpr int kSchemaVersion = 1;
// "ESLM": tells an edgeslam store from any other SQLite file.
constexpr int kStoreApplicationId = 0x45534c4d;

// Throws StoreError naming the file: not a store, damaged, or a newer version; writes nothing.
void checkSchema(SqliteDatabase& db, bool writable);
// After checkSchema: creates the schema of a new store or migrates an older one.
void prepareSchema(SqliteDatabase& db);

}  // namespace edgeslam
