#pragma once
// An edge session in the same process, reached without a network: uploads are handed to the
// session on a worker thread, slices come back on the session's mapping thread. For tests and
// for telling network effects apart from split effects.
#include <condition_variable>
#include <deque>
#include <memory>
#include <thread>

#include "modes/edge_link.h"
#include "server/edge_map_session.h"
#include "util/mutex.h"

namespace edgeslam {

class InProcessEdgeLink : public EdgeLink {
 public:
  InProcessEdgeLink(const PinholeCamera& camera, Sensor sensor, EdgeMapSessionOptions options);
  ~InProcessEdgeLink() override;

  void send(KeyFrameUpload upload) override;
  std::uint8_t idOrigin() const override { return 1; }
  void setSliceHandler(SliceHandler handler) override { handler_ = std::move(handler); }
  // Called on the worker thread for an upload the session refused.
  void setUploadDroppedHandler(UploadDroppedHandler handler) override;
  EdgeLinkCounters counters() const override;
  void close() override;
  // Waits until every sent upload is mapped and its slice handed over.
  void flush();
  EdgeMapSession& session() { return *session_; }

 private:
  void run();

  std::unique_ptr<EdgeMapSession> session_;
  SliceHandler handler_;
  UploadDroppedHandler dropped_handler_;  // guarded by mutex_
  std::uint64_t uploads_dropped_ = 0;     // guarded by mutex_
  mutable Mutex mutex_;
  std::condition_variable cv_;
  std::condition_variable drained_;
  bool busy_ GUARDED_BY(mutex_) = false;
  std::deque<KeyFrameUpload> queue_ GUARDED_BY(mutex_);
  bool closing_ GUARDED_BY(mutex_) = false;
  std::thread worker_;
};

}  // namespace edgeslam
