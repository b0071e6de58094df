#include "viz/viewed_session_factory.h"

#include <fmt/format.h>

#include <algorithm>
#include <utility>

namespace edgeslam::viz {
namespace {

// Passes every call on to the session's backend, shared with the directory so that a viewer
// sampling its map keeps it alive meanwhile; tells the directory when the session ends.
class ViewedSession : public EdgeSessionBackend {
 public:
  ViewedSession(std::shared_ptr<EdgeSessionBackend> backend, std::uint64_t session_id,
                std::shared_ptr<SessionDirectory> directory)
      : backend_(std::move(backend)), session_id_(session_id), directory_(std::move(directory)) {}
  ~ViewedSession() override { directory_->closed(session_id_); }
  ViewedSession(const ViewedSession&) = delete;
  ViewedSession& operator=(const ViewedSession&) = delete;

  void onKeyFrame(KeyFrameUpload upload) override { backend_->onKeyFrame(std::move(upload)); }
  std::optional<OffloadResult> onFrame(OffloadFrame frame) override {
    return backend_->onFrame(std::move(frame));
  }
  void onFullResyncRequested() override { backend_->onFullResyncRequested(); }
  std::uint64_t idFloor() const override { return backend_->idFloor(); }

 private:
  std::shared_ptr<EdgeSessionBackend> backend_;
  std::uint64_t session_id_;
  std::shared_ptr<SessionDirectory> directory_;
};

}  // namespace

void SessionDirectory::opened(Entry entry) {
  addEvent(entry.map_name.empty()
               ? fmt::format("session {} '{}' ({}) joined", entry.session_id, entry.client_name,
                             entry.sensor)
               : fmt::format("session {} '{}' ({}) joined, map '{}'", entry.session_id,
                             entry.client_name, entry.sensor, entry.map_name));
  MutexLock lock(mutex_);
  ++opened_;
  sessions_.push_back(std::move(entry));
}

void SessionDirectory::closed(std::uint64_t session_id) {
  std::string name;
  {
    MutexLock lock(mutex_);
    const auto it = std::find_if(sessions_.begin(), sessions_.end(),
                                 [&](const Entry& e) { return e.session_id == session_id; });
    if (it == sessions_.end()) return;
    name = it->client_name;
    sessions_.erase(it);
  }
  addEvent(fmt::format("session {} '{}' left", session_id, name));
}

void SessionDirectory::addEvent(std::string text) {
  MutexLock lock(mutex_);
  events_.push_back({std::chrono::system_clock::now(), std::move(text)});
  if (events_.size() > kMaxEvents) events_.pop_front();
}

std::vector<SessionDirectory::Entry> SessionDirectory::sessions() const {
  MutexLock lock(mutex_);
  return sessions_;
}

std::vector<ViewerEvent> SessionDirectory::events() const {
  MutexLock lock(mutex_);
  return {events_.begin(), events_.end()};
}

std::size_t SessionDirectory::openedCount() const {
  MutexLock lock(mutex_);
  return opened_;
}

ViewedSessionFactory::ViewedSessionFactory(std::shared_ptr<EdgeSessionFactory> inner,
                                           std::shared_ptr<SessionDirectory> directory)
    : inner_(std::move(inner)), directory_(std::move(directory)) {}

std::unique_ptr<EdgeSessionBackend> ViewedSessionFactory::open(const SessionConfig& config,
                                                               SliceSink& sink) {
  std::shared_ptr<EdgeSessionBackend> backend = inner_->open(config, sink);
  directory_->opened({.session_id = config.session_id,
                      .client_name = config.client_name,
                      .sensor = toString(config.sensor),
                      .map_name = config.map_name,
                      .backend = std::dynamic_pointer_cast<SlamSessionBackend>(backend)});
  return std::make_unique<ViewedSession>(std::move(backend), config.session_id, directory_);
}

}  // namespace edgeslam::viz
