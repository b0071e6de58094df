#pragma once
// The web viewer's HTTP server (cpp-httplib, on threads of its own):
//   GET /             the page          GET /app.js, /style.css  its script and style
//   GET /lib/...      the libraries the page loads (three.js, uPlot; see web_assets.h)
//   GET /api/state    the latest snapshot as JSON (view_snapshot.h)
//   GET /api/events   Server-Sent Events: the snapshot whenever it changed, at most `events_hz`
//                     times a second (a comment line keeps an idle stream alive)
//   GET /api/frame.jpg the camera image with its features (mobile view; 404 before the first)
//   GET /api/health   "ok"
// Anything else is 404. The files are built into the binary (web_assets.h).
#include <atomic>
#include <condition_variable>
#include <memory>
#include <stdexcept>
#include <string>
#include <thread>

#include "util/mutex.h"
#include "viz/view_source.h"

namespace httplib {
class Server;
}

namespace edgeslam::viz {

class ViewerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct ViewerServerOptions {
  std::string host = "127.0.0.1";
  int port = 0;  // 0 = a free port, chosen by the system
  double events_hz = 4.0;
  // The viewer's threads run at this nice value, so that on a shared core a frame is tracked
  // before a snapshot is encoded (util/thread_priority.h).
  int thread_nice = 10;
};

class ViewerServer {
 public:
  // Binds and starts serving; throws ViewerError when it cannot (a bad or taken port, a bad host).
  ViewerServer(ViewerServerOptions options, ViewSource& view);
  ~ViewerServer();
  ViewerServer(const ViewerServer&) = delete;
  ViewerServer& operator=(const ViewerServer&) = delete;

  int port() const { return port_; }
  std::string url() const;
  // Ends open event streams and joins the server's threads; idempotent (call from the owner's
  // thread).
  void stop();

 private:
  void addRoutes();
  // Sleeps for one event period, or less when stop() is called; false once stopping.
  bool waitForNextEvent();

  ViewerServerOptions options_;
  ViewSource& view_;
  std::unique_ptr<httplib::Server> server_;
  int port_ = 0;
  std::thread thread_;
  Mutex stop_mutex_;  // for stop_signal_ (stopping_ is atomic: the event streams poll it)
  std::condition_variable stop_signal_;
  std::atomic<bool> stopping_{false};
  std::atomic<bool> listening_ended_{false};
};

}  // namespace edgeslam::viz
