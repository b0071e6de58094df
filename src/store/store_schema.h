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

// Throws StoreError naming the file: not a store, damaged, or a newer version. `writable`: create
// or migrate when needed (a reader only checks).
void prepareSchema(SqliteDatabase& db, bool writable);

}  // namespace edgeslam
