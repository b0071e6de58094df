// The edge view's directory of sessions and its snapshot, without a server (the browser test
// drives the real `server --viewer` with a real client).
#include "viz/edge_view.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

namespace edgeslam::viz {
namespace {

TEST(EdgeView, ListsSessionsWithTheServersFiguresAndTheirComingsAndGoings) {
  auto directory = std::make_shared<SessionDirectory>();
  EdgeView view(directory, EdgeViewOptions{.refresh = std::chrono::milliseconds(0)});
  directory->opened({.session_id = 7, .client_name = "phone", .sensor = "rgbd", .backend = {}});
  view.setStatsSource([] {
    SessionStats stats;
    stats.session_id = 7;
    stats.uplink_bytes = 1234;
    return std::vector<SessionStats>{stats};
  });
  auto snapshot = nlohmann::json::parse(view.snapshotJson());
  EXPECT_EQ(snapshot["view"], "edge");
  ASSERT_EQ(snapshot["sessions"].size(), 1u);
  EXPECT_EQ(snapshot["sessions"][0]["session_id"], "7");
  EXPECT_EQ(snapshot["sessions"][0]["client_name"], "phone");
  EXPECT_EQ(snapshot["sessions"][0]["uplink_bytes"], 1234);
  EXPECT_TRUE(snapshot["sessions"][0]["camera"].is_null());  // no map yet
  const auto version = snapshot["version"].get<std::uint64_t>();
  // Unchanged: the same version; a session leaving: a new one, listed in the events.
  EXPECT_EQ(nlohmann::json::parse(view.snapshotJson())["version"], version);
  directory->closed(7);
  view.clearStatsSource();
  snapshot = nlohmann::json::parse(view.snapshotJson());
  EXPECT_GT(snapshot["version"].get<std::uint64_t>(), version);
  EXPECT_EQ(snapshot["sessions"].size(), 0u);
  EXPECT_EQ(snapshot["status"]["sessions_opened"], 1);
  ASSERT_EQ(snapshot["events"].size(), 2u);
  EXPECT_NE(snapshot["events"][0]["text"].get<std::string>().find("joined"), std::string::npos);
  EXPECT_NE(snapshot["events"][1]["text"].get<std::string>().find("left"), std::string::npos);
}

}  // namespace
}  // namespace edgeslam::viz
