#include "viz/viewer_server.h"

#include <fmt/format.h>
#include <httplib.h>
#include <sys/socket.h>

#include <chrono>
#include <csignal>

#include "util/thread_priority.h"
#include "viz/web_assets.h"

namespace edgeslam::viz {
namespace {

// httplib's threads come from its own pool: each lowers itself the first time it serves.
void runAtNice(int nice) {
  thread_local bool done = false;
  if (done) return;
  done = true;
  const int increment = nice - currentThreadNice();
  if (increment > 0) lowerCurrentThreadPriority(increment);
}

}  // namespace

ViewerServer::ViewerServer(ViewerServerOptions options, ViewSource& view)
    : options_(std::move(options)), view_(view), server_(std::make_unique<httplib::Server>()) {
  if (options_.port < 0 || options_.port > 65535) {
    throw ViewerError(
        fmt::format("viewer port {} is out of range (0-65535; 0 = any free port)", options_.port));
  }
  if (!(options_.events_hz > 0.0)) throw ViewerError("viewer events_hz must be positive");
  // A browser closing its tab mid-stream would otherwise end the process: httplib writes to
  // sockets without MSG_NOSIGNAL.
  std::signal(SIGPIPE, SIG_IGN);
  // An idle keep-alive connection holds a worker for this long, also when stopping.
  server_->set_keep_alive_timeout(1);
  // httplib's default, SO_REUSEPORT, would let a second viewer share a port that is in use.
  server_->set_socket_options([](socket_t sock) {
    const int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
  });
  addRoutes();
  if (options_.port == 0) {
    port_ = server_->bind_to_any_port(options_.host);
  } else if (server_->bind_to_port(options_.host, options_.port)) {
    port_ = options_.port;
  } else {
    port_ = -1;
  }
  if (port_ <= 0) {
    throw ViewerError(fmt::format("viewer: cannot listen on {}:{} (port in use or bad host)",
                                  options_.host, options_.port));
  }
  thread_ = std::thread([this] {
    server_->listen_after_bind();
    listening_ended_ = true;
  });
  // stop() before the loop runs would be lost (httplib ignores it) and join would hang.
  while (!server_->is_running() && !listening_ended_) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

ViewerServer::~ViewerServer() {
  stop();
}

std::string ViewerServer::url() const {
  return fmt::format("http://{}:{}/", options_.host, port_);
}

void ViewerServer::stop() {
  {
    MutexLock lock(stop_mutex_);
    stopping_ = true;
  }
  stop_signal_.notify_all();
  server_->stop();
  if (thread_.joinable()) thread_.join();
}

bool ViewerServer::waitForNextEvent() {
  const auto period = std::chrono::duration<double>(1.0 / options_.events_hz);
  MutexLock lock(stop_mutex_);
  lock.waitFor(stop_signal_, period, [this] { return stopping_.load(); });
  return !stopping_;
}

void ViewerServer::addRoutes() {
  for (const WebAsset& asset : webAssets()) {
    server_->Get(std::string(asset.path), [asset](const httplib::Request&, httplib::Response& res) {
      res.set_header("Cache-Control", "no-cache");
      res.set_content(asset.body.data(), asset.body.size(),
                      std::string(asset.content_type).c_str());
    });
  }
  server_->Get("/api/health", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("ok\n", "text/plain");
  });
  server_->Get("/api/state", [this](const httplib::Request&, httplib::Response& res) {
    runAtNice(options_.thread_nice);
    res.set_header("Cache-Control", "no-cache");
    res.set_content(view_.snapshotJson(), "application/json");
  });
  server_->Get("/api/map", [this](const httplib::Request& req, httplib::Response& res) {
    runAtNice(options_.thread_nice);
    res.set_header("Cache-Control", "no-cache");
    const std::string name = req.get_param_value("name");
    std::optional<std::string> json;
    try {
      if (!name.empty()) json = view_.storedMapJson(name);
    } catch (const std::exception& e) {
      res.status = 500;
      res.set_content(std::string("the map cannot be read: ") + e.what() + "\n", "text/plain");
      return;
    }
    if (!json) {
      res.status = 404;
      res.set_content("no such map\n", "text/plain");
      return;
    }
    res.set_content(std::move(*json), "application/json");
  });
  server_->Get("/api/frame.jpg", [this](const httplib::Request&, httplib::Response& res) {
    runAtNice(options_.thread_nice);
    res.set_header("Cache-Control", "no-store");
    FrameImageSlot* images = view_.images();
    std::optional<std::string> jpeg = images ? images->jpeg() : std::nullopt;
    if (!jpeg) {
      res.status = 404;
      res.set_content("no camera image\n", "text/plain");
      return;
    }
    res.set_content(std::move(*jpeg), "image/jpeg");
  });
  server_->Get("/api/events", [this](const httplib::Request&, httplib::Response& res) {
    res.set_header("Cache-Control", "no-cache");
    res.set_header("X-Accel-Buffering", "no");
    auto last_sent = std::make_shared<std::string>();
    res.set_chunked_content_provider(
        "text/event-stream", [this, last_sent](std::size_t, httplib::DataSink& sink) {
          runAtNice(options_.thread_nice);
          if (stopping_) return false;
          std::string json = view_.snapshotJson();
          const std::string message =
              json == *last_sent ? std::string(": unchanged\n\n") : "data: " + json + "\n\n";
          if (!sink.write(message.data(), message.size())) return false;
          *last_sent = std::move(json);
          return waitForNextEvent();
        });
  });
}

}  // namespace edgeslam::viz
