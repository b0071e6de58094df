// Routes are saved with their map (schema version 3): replaced by name, listed, removed alone or
// with the map, refused for a map that does not exist, and absent (not an error) in a store of an
// older version read as it is.
#include <gtest/gtest.h>
#include <sqlite3.h>

#include "store/map_store.h"
#include "store/store_error.h"
#include "store_fixture.h"

namespace edgeslam {
namespace {

RouteRecord routeNamed(const std::string& name, std::size_t checkpoints) {
  RouteRecord route;
  route.name = name;
  route.source = "test";
  route.spacing_m = 0.5;
  route.up = Eigen::Vector3d(0.1, -0.99, 0.05).normalized();
  for (std::size_t i = 0; i < checkpoints; ++i) {
    route.checkpoints.emplace_back(0.5 * static_cast<double>(i), 1e-9 * static_cast<double>(i),
                                   -3.25);
  }
  return route;
}

TEST(MapStoreRoutes, SavedListedReplacedAndRemovedWithTheirMap) {
  const auto dir = test::freshStoreDir("routes");
  const test::SmallMap small;
  {
    auto store = openMapStore(dir, MapStoreAccess::kServe);
    store->beginSession("kitchen", small.info());
    store->beginSession("hall", small.info());
    EXPECT_THROW(store->saveRoute("nowhere", routeNamed("a", 2)), StoreError);
    store->saveRoute("kitchen", routeNamed("walk", 5));
    store->saveRoute("kitchen", routeNamed("back", 3));
    store->saveRoute("hall", routeNamed("walk", 4));
    store->saveRoute("kitchen", routeNamed("walk", 6));  // replaces
  }
  {
    auto reader = openMapStore(dir, MapStoreAccess::kRead);
    const auto routes = reader->listRoutes("kitchen");
    ASSERT_EQ(routes.size(), 2u);
    EXPECT_EQ(routes[0].name, "back");  // by name
    const RouteRecord expected = routeNamed("walk", 6);
    const RouteRecord& walk = routes[1];
    EXPECT_EQ(walk.name, "walk");
    EXPECT_EQ(walk.source, "test");
    EXPECT_EQ(walk.spacing_m, 0.5);
    EXPECT_EQ(walk.up, expected.up);
    EXPECT_EQ(walk.checkpoints, expected.checkpoints);  // bit for bit
    EXPECT_GT(walk.created, 1.7e9);
    EXPECT_EQ(reader->listRoutes("hall").size(), 1u);
    EXPECT_TRUE(reader->listRoutes("nowhere").empty());
  }
  {
    auto editor = openMapStore(dir, MapStoreAccess::kEdit);
    EXPECT_TRUE(editor->removeRoute("kitchen", "back"));
    EXPECT_FALSE(editor->removeRoute("kitchen", "back"));
    EXPECT_TRUE(editor->removeMap("kitchen"));
    EXPECT_TRUE(editor->listRoutes("kitchen").empty());
    EXPECT_EQ(editor->listRoutes("hall").size(), 1u);
  }
  // The kitchen's route went with it: only the hall's row is left.
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "maps.sqlite").c_str(), &db), SQLITE_OK);
  sqlite3_stmt* count = nullptr;
  ASSERT_EQ(sqlite3_prepare_v2(db, "SELECT count(*) FROM routes", -1, &count, nullptr), SQLITE_OK);
  ASSERT_EQ(sqlite3_step(count), SQLITE_ROW);
  EXPECT_EQ(sqlite3_column_int(count, 0), 1);
  sqlite3_finalize(count);
  sqlite3_close(db);
  std::filesystem::remove_all(dir);
}

TEST(MapStoreRoutes, AStoreOfAnOlderVersionReadAsItIsHasNone) {
  const auto dir = test::freshStoreDir("routes_v2");
  const test::SmallMap small;
  openMapStore(dir, MapStoreAccess::kServe)->beginSession("kitchen", small.info());
  sqlite3* db = nullptr;
  ASSERT_EQ(sqlite3_open((dir / "maps.sqlite").c_str(), &db), SQLITE_OK);
  ASSERT_EQ(
      sqlite3_exec(db, "DROP TABLE routes; PRAGMA user_version = 2", nullptr, nullptr, nullptr),
      SQLITE_OK);
  sqlite3_close(db);
  EXPECT_TRUE(openMapStore(dir, MapStoreAccess::kRead)->listRoutes("kitchen").empty());
  // A writer migrates it, and routes can be saved.
  auto writer = openMapStore(dir, MapStoreAccess::kServe);
  writer->saveRoute("kitchen", routeNamed("walk", 2));
  EXPECT_EQ(writer->listRoutes("kitchen").size(), 1u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace edgeslam
