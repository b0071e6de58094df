// Several clients in one named map on a real edge server: a client naming a map another client is
// writing joins it (one map), clients that cannot share it are refused with the reason, unnamed
// maps stay apart, and the map outlives the client that made it while another writes it.
#include <gtest/gtest.h>

#include <chrono>
#include <functional>
#include <string>
#include <thread>

#include "modes/slam_session_backend.h"
#include "wire/edge_client.h"
#include "wire/edge_server.h"
#include "wire/net_test_records.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;

EdgeClientOptions clientOptions() {
  EdgeClientOptions options;
  options.connect_timeout = 10s;
  return options;
}

SessionConfig kitchenClient(const std::string& name) {
  SessionConfig config = test::sampleSessionConfig(name);
  config.map_name = "kitchen";
  return config;
}

bool eventually(const std::function<bool()>& condition) {
  const auto until = std::chrono::steady_clock::now() + 10s;
  while (!condition()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(10ms);
  }
  return true;
}

std::string refusal(const EdgeServer& server, const SessionConfig& config) {
  try {
    EdgeClient client(server.address(), config, clientOptions());
  } catch (const EdgeClientError& e) {
    return e.what();
  }
  return "";
}

TEST(SharedMapSessions, ASecondClientNamingALiveMapJoinsIt) {
  EdgeServer server("127.0.0.1:0", std::make_shared<SlamSessionFactory>());
  EdgeClient first(server.address(), kitchenClient("first"), clientOptions());
  EdgeClient second(server.address(), kitchenClient("second"), clientOptions());
  EdgeClient elsewhere(server.address(), test::sampleSessionConfig("elsewhere"), clientOptions());
  EXPECT_EQ(server.sessionCount(), 3u);
  EXPECT_NE(first.idOrigin(), second.idOrigin());  // their ids never collide in the one map

  // The map outlives the client that made it: a third one joins it while the second writes.
  first.close();
  EXPECT_TRUE(eventually([&] { return server.sessionCount() == 2; }));
  EdgeClient third(server.address(), kitchenClient("third"), clientOptions());
  EXPECT_EQ(server.sessionCount(), 3u);
}

TEST(SharedMapSessions, AClientThatCannotShareTheMapIsRefusedWithTheReason) {
  EdgeServer server("127.0.0.1:0", std::make_shared<SlamSessionFactory>());
  EdgeClient writer(server.address(), kitchenClient("writer"), clientOptions());

  SessionConfig mono = kitchenClient("mono");
  mono.sensor = Sensor::kMonocular;
  EXPECT_NE(refusal(server, mono).find("cannot join it: it is mapped with a rgbd sensor"),
            std::string::npos)
      << refusal(server, mono);

  SessionConfig other_camera = kitchenClient("other-camera");
  CameraIntrinsics intrinsics = other_camera.camera.intrinsics();
  intrinsics.fx = 500.0;
  other_camera.camera = PinholeCamera(intrinsics);
  EXPECT_NE(refusal(server, other_camera).find("it is mapped with another camera"),
            std::string::npos);

  SessionConfig whole_map = kitchenClient("whole-map");
  whole_map.settings.client_map_keyframes = 0;
  EXPECT_NE(refusal(server, whole_map).find("needs a bounded one"), std::string::npos);

  EXPECT_EQ(server.sessionCount(), 1u);
}

}  // namespace
}  // namespace edgeslam
