#pragma once
// The edge server's sessions as the edge view sees them: a factory that opens sessions through
// another one and keeps a directory of them (who joined, who left, a handle to sample each one's
// map while it lives).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "modes/slam_session_backend.h"
#include "util/mutex.h"
#include "wire/edge_server.h"

namespace edgeslam::viz {

struct ViewerEvent {
  std::chrono::system_clock::time_point time;
  std::string text;
};

class SessionDirectory {
 public:
  struct Entry {
    std::uint64_t session_id = 0;
    std::string client_name;
    std::string sensor;
    std::string map_name;  // as the client named it ("" for a map of its own)
    // Sampling holds the backend for that long; nullptr when the factory's backends are not
    // SlamSessionBackends (nothing to sample).
    std::weak_ptr<SlamSessionBackend> backend;
  };

  void opened(Entry entry);
  void closed(std::uint64_t session_id);
  void addEvent(std::string text);

  std::vector<Entry> sessions() const;
  std::vector<ViewerEvent> events() const;  // the latest `kMaxEvents`, oldest first
  std::size_t openedCount() const;

  static constexpr std::size_t kMaxEvents = 100;

 private:
  mutable Mutex mutex_;
  std::vector<Entry> sessions_ GUARDED_BY(mutex_);
  std::deque<ViewerEvent> events_ GUARDED_BY(mutex_);
  std::size_t opened_ GUARDED_BY(mutex_) = 0;
};

class ViewedSessionFactory : public EdgeSessionFactory {
 public:
  ViewedSessionFactory(std::shared_ptr<EdgeSessionFactory> inner,
                       std::shared_ptr<SessionDirectory> directory);
  std::unique_ptr<EdgeSessionBackend> open(const SessionConfig& config, SliceSink& sink) override;

 private:
  std::shared_ptr<EdgeSessionFactory> inner_;
  std::shared_ptr<SessionDirectory> directory_;
};

}  // namespace edgeslam::viz
