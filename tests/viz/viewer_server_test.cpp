// The viewer's HTTP server on a free loopback port, talked to with httplib's client.
#include "viz/viewer_server.h"

// clang-format off: before httplib.h, whose macros break Eigen's headers.
#include "viz/frame_image.h"
#include "viz/live_view.h"
// clang-format on
#include <gtest/gtest.h>
#include <httplib.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <future>
#include <nlohmann/json.hpp>
#include <thread>

namespace edgeslam::viz {
namespace {

using namespace std::chrono_literals;

// Limits are generous: a busy 2-core CI machine may be slow, never this slow.
constexpr auto kPatience = 30s;

class ViewerServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    view_.setMapSampler([](std::size_t) {
      MapSample sample;
      sample.keyframe_poses.push_back(SE3d());
      sample.points = {{1, 2, 3}, {4, 5, 6}};
      sample.total_points = 2;
      return sample;
    });
    RunStatus status;
    status.frame = 3;
    status.frames_total = 10;
    status.mode = "local";
    view_.publishFrame(status, SE3d(), std::nullopt);
    server_ = std::make_unique<ViewerServer>(ViewerServerOptions{.port = 0}, view_);
  }

  httplib::Client client() {
    httplib::Client c("127.0.0.1", server_->port());
    c.set_connection_timeout(10);
    c.set_read_timeout(30);
    return c;
  }

  LiveView view_;
  std::unique_ptr<ViewerServer> server_;
};

TEST_F(ViewerServerTest, ServesThePageScriptAndStyle) {
  ASSERT_GT(server_->port(), 0);
  EXPECT_EQ(server_->url(), "http://127.0.0.1:" + std::to_string(server_->port()) + "/");
  auto c = client();
  const auto page = c.Get("/");
  ASSERT_TRUE(page) << httplib::to_string(page.error());
  EXPECT_EQ(page->status, 200);
  EXPECT_NE(page->body.find("<div id=\"view\""), std::string::npos);
  EXPECT_NE(page->body.find("importmap"), std::string::npos);
  EXPECT_NE(page->get_header_value("Content-Type").find("text/html"), std::string::npos);
  const auto script = c.Get("/app.js");
  ASSERT_TRUE(script);
  EXPECT_EQ(script->status, 200);
  EXPECT_NE(script->body.find("EventSource"), std::string::npos);
  EXPECT_NE(script->get_header_value("Content-Type").find("javascript"), std::string::npos);
  const auto style = c.Get("/style.css");
  ASSERT_TRUE(style);
  EXPECT_EQ(style->status, 200);
  // The libraries the page loads are served from the binary: it works without internet.
  for (const char* path : {"/lib/three.module.min.js", "/lib/three.core.min.js",
                           "/lib/OrbitControls.js", "/lib/uPlot.iife.min.js"}) {
    const auto library = c.Get(path);
    ASSERT_TRUE(library) << path;
    EXPECT_EQ(library->status, 200) << path;
    EXPECT_GT(library->body.size(), 10000u) << path;
    EXPECT_NE(library->get_header_value("Content-Type").find("javascript"), std::string::npos);
  }
  const auto library_style = c.Get("/lib/uPlot.min.css");
  ASSERT_TRUE(library_style);
  EXPECT_EQ(library_style->status, 200);
  EXPECT_NE(library_style->body.find(".uplot"), std::string::npos);
  const auto health = c.Get("/api/health");
  ASSERT_TRUE(health);
  EXPECT_EQ(health->status, 200);
  EXPECT_EQ(health->body, "ok\n");
}

TEST_F(ViewerServerTest, UnknownPathsAre404) {
  auto c = client();
  // A view without stored maps (the mobile view) has none to show.
  for (const char* path : {"/nope", "/api/nope", "/app.js.map", "/index.html/..", "/api/map",
                           "/api/map?name=kitchen", "/api/map?name=..%2F..%2Fetc"}) {
    const auto res = c.Get(path);
    ASSERT_TRUE(res) << path;
    EXPECT_EQ(res->status, 404) << path;
  }
}

TEST_F(ViewerServerTest, StateIsTheSnapshotAsJson) {
  auto c = client();
  const auto res = c.Get("/api/state");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  EXPECT_NE(res->get_header_value("Content-Type").find("application/json"), std::string::npos);
  const auto state = nlohmann::json::parse(res->body);
  for (const char* key : {"version", "status", "camera", "trajectory", "ground_truth", "keyframes",
                          "points", "points_total"}) {
    EXPECT_TRUE(state.contains(key)) << key;
  }
  EXPECT_EQ(state["status"]["frame"], 3);
  EXPECT_EQ(state["status"]["mode"], "local");
  EXPECT_EQ(state["points"].size(), 6u);
  EXPECT_EQ(state["keyframes"].size(), 1u);
}

TEST_F(ViewerServerTest, CameraImageIsAJpegOnceTheRunPublishesOne) {
  auto c = client();
  const auto none = c.Get("/api/frame.jpg");
  ASSERT_TRUE(none);
  EXPECT_EQ(none->status, 404);
  // The page asked: the run loop is now asked for an image, and only then.
  FrameImageSlot& images = *view_.images();
  ASSERT_TRUE(images.wanted());
  FrameImage frame;
  frame.image = cv::Mat(240, 320, CV_8UC1, cv::Scalar(128));
  frame.on_map = {{10, 10}, {100, 50}};
  frame.fresh = {{150, 60}};
  frame.culled = {{200, 100}};
  frame.mask = cv::Mat1b(240, 320, std::uint8_t{0});
  images.publish(std::move(frame));
  const auto jpeg = c.Get("/api/frame.jpg");
  ASSERT_TRUE(jpeg);
  EXPECT_EQ(jpeg->status, 200);
  EXPECT_EQ(jpeg->get_header_value("Content-Type"), "image/jpeg");
  ASSERT_GT(jpeg->body.size(), 2u);
  EXPECT_EQ(static_cast<unsigned char>(jpeg->body[0]), 0xFF);
  EXPECT_EQ(static_cast<unsigned char>(jpeg->body[1]), 0xD8);
}

// Each feature state is drawn in its own colour where the feature is, on a grey frame.
TEST(FrameImage, FeaturesAreDrawnInTheColourOfTheirState) {
  FrameImage frame;
  frame.image = cv::Mat(240, 320, CV_8UC1, cv::Scalar(128));
  frame.on_map = {{40, 40}};
  frame.fresh = {{120, 40}};
  frame.culled = {{200, 40}};
  const cv::Mat canvas = renderFrame(frame);
  ASSERT_EQ(canvas.type(), CV_8UC3);
  ASSERT_EQ(canvas.size(), cv::Size(320, 240));
  // The most saturated pixel near a point has the colour of its state.
  const auto strongest = [&](cv::Point2f at) {
    cv::Vec3b best(128, 128, 128);
    int best_spread = -1;
    for (int dy = -4; dy <= 4; ++dy) {
      for (int dx = -4; dx <= 4; ++dx) {
        const cv::Vec3b c =
            canvas.at<cv::Vec3b>(static_cast<int>(at.y) + dy, static_cast<int>(at.x) + dx);
        const int spread = std::max({c[0], c[1], c[2]}) - std::min({c[0], c[1], c[2]});
        if (spread > best_spread) {
          best_spread = spread;
          best = c;
        }
      }
    }
    return best;
  };
  const auto dominant = [](cv::Vec3b c) {  // 0 blue, 1 green, 2 red
    return static_cast<int>(std::max_element(&c[0], &c[0] + 3) - &c[0]);
  };
  EXPECT_EQ(dominant(strongest(frame.on_map[0])), 1);
  EXPECT_EQ(dominant(strongest(frame.fresh[0])), 0);
  EXPECT_EQ(dominant(strongest(frame.culled[0])), 2);
  // Away from every feature the frame is untouched.
  EXPECT_EQ(canvas.at<cv::Vec3b>(200, 160), cv::Vec3b(128, 128, 128));
}

TEST(FrameImageSlot, WantedOnlyWhileAPageAsksAndAtMostAtItsRate) {
  // One image per 2 s at most; a page counts as gone 0.5 s after its last request.
  FrameImageSlot slot(0.5, std::chrono::milliseconds(500));
  EXPECT_FALSE(slot.wanted());
  EXPECT_FALSE(slot.jpeg().has_value());
  EXPECT_TRUE(slot.wanted());
  slot.publish(FrameImage{.image = cv::Mat(8, 8, CV_8UC1, cv::Scalar(0)),
                          .on_map = {},
                          .fresh = {},
                          .culled = {},
                          .mask = {}});
  EXPECT_FALSE(slot.wanted());  // the next one only 2 s after this
  EXPECT_TRUE(slot.jpeg().has_value());
  std::this_thread::sleep_for(600ms);
  EXPECT_FALSE(slot.wanted());  // and the page is gone by then
}

// Reads /api/events on a thread of its own until it ends; counts the data events.
struct EventReader {
  explicit EventReader(int port)
      : thread([this, port] {
          httplib::Client c("127.0.0.1", port);
          c.set_connection_timeout(10);
          c.set_read_timeout(60);
          std::string buffer;
          (void)c.Get("/api/events", [&](const char* data, std::size_t size) {
            buffer.append(data, size);
            for (std::size_t end; (end = buffer.find("\n\n")) != std::string::npos;) {
              const std::string message = buffer.substr(0, end);
              buffer.erase(0, end + 2);
              if (message.rfind("data: ", 0) == 0) {
                if (data_events++ == 0) first.set_value(message.substr(6));
              }
            }
            return !stop_reading;
          });
          ended = true;
        }) {}
  ~EventReader() {
    stop_reading = true;
    thread.join();
  }

  std::promise<std::string> first;
  std::future<std::string> first_data = first.get_future();
  std::atomic<int> data_events{0};
  std::atomic<bool> stop_reading{false};
  std::atomic<bool> ended{false};
  std::thread thread;
};

TEST_F(ViewerServerTest, EventsDeliverTheSnapshot) {
  EventReader reader(server_->port());
  ASSERT_EQ(reader.first_data.wait_for(kPatience), std::future_status::ready);
  const auto event = nlohmann::json::parse(reader.first_data.get());
  EXPECT_EQ(event["status"]["frame"], 3);
  // A change is pushed too.
  RunStatus status;
  status.frame = 4;
  view_.publishFrame(status, SE3d(), std::nullopt);
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (reader.data_events < 2 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_GE(reader.data_events.load(), 2);
  server_->stop();
}

TEST_F(ViewerServerTest, StopsPromptlyWhileAStreamIsOpen) {
  EventReader reader(server_->port());
  ASSERT_EQ(reader.first_data.wait_for(kPatience), std::future_status::ready);
  const auto start = std::chrono::steady_clock::now();
  server_->stop();
  // The stream ends within an event period; the bound only catches a hang (httplib would
  // otherwise wait for the client).
  EXPECT_LT(std::chrono::steady_clock::now() - start, 10s);
  const auto deadline = std::chrono::steady_clock::now() + kPatience;
  while (!reader.ended && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(10ms);
  }
  EXPECT_TRUE(reader.ended.load());
  server_->stop();  // again: nothing happens
}

TEST(ViewerServer, BadPortsAreClearErrors) {
  LiveView view;
  EXPECT_THROW(ViewerServer(ViewerServerOptions{.port = -1}, view), ViewerError);
  EXPECT_THROW(ViewerServer(ViewerServerOptions{.port = 65536}, view), ViewerError);
  ViewerServer first(ViewerServerOptions{.port = 0}, view);
  try {
    ViewerServer second(ViewerServerOptions{.port = first.port()}, view);
    ADD_FAILURE() << "a port in use was taken again";
  } catch (const ViewerError& e) {
    EXPECT_NE(std::string(e.what()).find(std::to_string(first.port())), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace edgeslam::viz
