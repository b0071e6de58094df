#pragma once
// The edge view (`server --viewer`): every session the edge server holds, each one's map
// (points, keyframes, the client's trajectory and latest position) and figures, the sessions
// joining and leaving, the loops closed. The maps are sampled by the viewer's threads, at most
// once per `refresh` and only while a page asks; the server's threads never wait for a viewer
// beyond the map's update mutex.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "util/mutex.h"
#include "viz/view_source.h"
#include "viz/viewed_session_factory.h"
#include "wire/edge_server.h"

namespace edgeslam::viz {

struct EdgeViewOptions {
  std::size_t max_points = 20000;    // over all sessions
  std::size_t max_keyframes = 2000;  // per session
  std::chrono::milliseconds refresh{500};
};

class EdgeView : public ViewSource {
 public:
  using StatsSource = std::function<std::vector<SessionStats>()>;

  explicit EdgeView(std::shared_ptr<SessionDirectory> directory, EdgeViewOptions options = {});
  // The server's per-session figures (EdgeServer::sessions); cleared before the server goes.
  void setStatsSource(StatsSource source);
  void clearStatsSource();

  std::string snapshotJson() override;

 private:
  std::string buildJson() REQUIRES(mutex_);

  std::shared_ptr<SessionDirectory> directory_;
  EdgeViewOptions options_;
  Mutex mutex_;
  StatsSource stats_ GUARDED_BY(mutex_);
  std::uint64_t version_ GUARDED_BY(mutex_) = 0;
  std::map<std::uint64_t, std::size_t> loops_seen_ GUARDED_BY(mutex_);  // by session
  std::size_t loops_total_ GUARDED_BY(mutex_) = 0;
  std::optional<std::chrono::steady_clock::time_point> built_at_ GUARDED_BY(mutex_);
  std::string encoded_ GUARDED_BY(mutex_);
  std::string last_body_ GUARDED_BY(mutex_);
};

}  // namespace edgeslam::viz
