#pragma once
// The real split: keyframe uploads and map slices over gRPC to an edge server session.
#include <memory>
#include <string>

#include "modes/edge_link.h"
#include "util/mutex.h"
#include "wire/edge_client.h"

namespace edgeslam {

class GrpcEdgeLink : public EdgeLink {
 public:
  // Connects and opens the session; throws EdgeClientError when the server cannot be reached.
  GrpcEdgeLink(const std::string& server_address, SessionConfig config,
               EdgeClientOptions options = {});
  ~GrpcEdgeLink() override;

  void send(KeyFrameUpload upload) override;
  std::uint8_t idOrigin() const override { return client_->idOrigin(); }
  std::uint64_t idFloor() const override { return client_->idFloor(); }
  bool reconnecting() const override { return client_->reconnecting(); }
  std::vector<KeyFrameId> pendingKeyFrames() const override {
    return client_->pendingUploadKeyFrames();
  }
  void setSliceHandler(SliceHandler handler) override;
  void setUploadDroppedHandler(UploadDroppedHandler handler) override;
  EdgeLinkCounters counters() const override;
  void close() override;

  EdgeClient& client() { return *client_; }
  EdgeClient* edgeClient() override { return client_.get(); }

 private:
  void deliver(MapSlice slice);
  void reportDropped(std::uint64_t sequence, KeyFrameId keyframe);

  Mutex handler_mutex_;
  SliceHandler handler_ GUARDED_BY(handler_mutex_);
  Mutex dropped_mutex_;
  UploadDroppedHandler dropped_handler_ GUARDED_BY(dropped_mutex_);
  std::unique_ptr<EdgeClient> client_;
};

}  // namespace edgeslam
