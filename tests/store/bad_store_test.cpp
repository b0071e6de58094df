// Stores that cannot be used: each gives one line naming the file, and the file is left as it was.
#include <gtest/gtest.h>
#include <sqlite3.h>
#include <unistd.h>

#include <fstream>
#include <iterator>

#include "store/map_store.h"
#include "store/store_error.h"
#include "store/store_schema.h"
#include "store_fixture.h"

namespace edgeslam {
namespace {

using test::freshStoreDir;

std::string readBytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// A store with one map, closed (checkpointed: the whole store in the one file).
std::filesystem::path storeWithAMap(const std::string& name) {
  const auto dir = freshStoreDir(name);
  test::writeSmallMap(*openMapStore(dir, MapStoreAccess::kServe), "m");
  return dir;
}

// Opening fails for every access with one line naming the file, saying `words` (or, for damage,
// SQLite's own word for it), and changes no byte of it.
void expectRefused(const std::filesystem::path& dir, const std::string& words) {
  const auto file = dir / "maps.sqlite";
  const std::string before = readBytes(file);
  for (const MapStoreAccess access :
       {MapStoreAccess::kRead, MapStoreAccess::kEdit, MapStoreAccess::kServe}) {
    try {
      auto store = openMapStore(dir, access);
      // A damage quick_check cannot see must still fail when the map is read.
      store->loadMap("m");
      ADD_FAILURE() << "opened a bad store (" << words << ")";
    } catch (const StoreError& e) {
      const std::string message = e.what();
      EXPECT_NE(message.find(file.string()), std::string::npos) << message;
      const bool damage_named =
          words == "malformed" && (message.find("not a database") != std::string::npos);
      EXPECT_TRUE(message.find(words) != std::string::npos || damage_named) << message;
      EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    }
  }
  EXPECT_TRUE(readBytes(file) == before) << "the bad store was changed";
}

TEST(BadStore, NewerSchemaIsRefused) {
  const auto dir = storeWithAMap("newer");
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "maps.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "PRAGMA user_version = 99", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  expectRefused(dir, "schema version 99 is newer");
  std::filesystem::remove_all(dir);
}

TEST(BadStore, AnotherSqliteFileIsNotAStore) {
  const auto dir = freshStoreDir("foreign");
  std::filesystem::create_directories(dir);
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "maps.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(sqlite3_exec(db, "CREATE TABLE t(x)", nullptr, nullptr, nullptr), SQLITE_OK);
  sqlite3_close(db);
  expectRefused(dir, "not an edgeslam map store");
  std::filesystem::remove_all(dir);
}

TEST(BadStore, GarbageIsRefused) {
  const auto dir = freshStoreDir("garbage");
  std::filesystem::create_directories(dir);
  std::ofstream(dir / "maps.sqlite") << std::string(5000, 'x');
  expectRefused(dir, "not a database");
  std::filesystem::remove_all(dir);
}

TEST(BadStore, TruncatedStoreIsRefused) {
  const auto dir = storeWithAMap("truncated");
  const auto file = dir / "maps.sqlite";
  const auto size = std::filesystem::file_size(file);
  ASSERT_GT(size, 8192u);
  std::filesystem::resize_file(file, size / 2);
  expectRefused(dir, "malformed");
  std::filesystem::remove_all(dir);
}

// The b-tree pages the store is found through (page 1: the schema). Damage inside blob payloads is
// not detected: the store keeps no checksums of its own.
TEST(BadStore, OverwrittenSchemaPageIsRefused) {
  const auto dir = storeWithAMap("overwritten");
  const auto file = dir / "maps.sqlite";
  {
    std::fstream io(file, std::ios::in | std::ios::out | std::ios::binary);
    io.seekp(100);
    io << std::string(1000, '\x5a');
  }
  expectRefused(dir, "malformed");
  std::filesystem::remove_all(dir);
}

TEST(BadStore, SecondWriterIsLockedOut) {
  const auto dir = storeWithAMap("locked");
  auto first = openMapStore(dir, MapStoreAccess::kServe);
  try {
    openMapStore(dir, MapStoreAccess::kServe);
    ADD_FAILURE() << "two writers on one store";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("locked by another edgeslam process"), std::string::npos)
        << e.what();
  }
  // Readers may look while the server writes.
  EXPECT_TRUE(openMapStore(dir, MapStoreAccess::kRead)->mapInfo("m"));
  first.reset();
  EXPECT_NO_THROW(openMapStore(dir, MapStoreAccess::kServe));
  std::filesystem::remove_all(dir);
}

TEST(BadStore, MissingStoreIsAnErrorForReaders) {
  const auto dir = freshStoreDir("missing");
  try {
    openMapStore(dir, MapStoreAccess::kRead);
    ADD_FAILURE() << "opened a store that is not there";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find((dir / "maps.sqlite").string()), std::string::npos);
  }
  EXPECT_FALSE(std::filesystem::exists(dir));
}

TEST(BadStore, ReadOnlyStoreIsRefusedToWriters) {
  if (::geteuid() == 0) GTEST_SKIP() << "root writes through file permissions";
  const auto dir = storeWithAMap("readonly");
  std::filesystem::permissions(dir / "maps.sqlite", std::filesystem::perms::owner_read);
  try {
    openMapStore(dir, MapStoreAccess::kServe);
    ADD_FAILURE() << "wrote to a read-only store";
  } catch (const StoreError& e) {
    EXPECT_NE(std::string(e.what()).find("read-only"), std::string::npos) << e.what();
  }
  std::filesystem::permissions(dir / "maps.sqlite", std::filesystem::perms::owner_all);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace edgeslam
