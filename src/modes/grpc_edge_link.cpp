#include "modes/grpc_edge_link.h"

#include <spdlog/spdlog.h>

namespace edgeslam {

GrpcEdgeLink::GrpcEdgeLink(const std::string& server_address, SessionConfig config,
                           EdgeClientOptions options) {
  options.on_slice = [this](MapSlice slice) { deliver(std::move(slice)); };
  options.on_upload_dropped = [this](std::uint64_t sequence, KeyFrameId keyframe) {
    reportDropped(sequence, keyframe);
  };
  options.on_session_event = [](const EdgeSessionEvent& event) {
    if (event.reopened) spdlog::warn("edge session reopened: {}", event.reason);
    if (event.full_resync_needed) spdlog::warn("edge asks for a full resync: {}", event.reason);
  };
  client_ = std::make_unique<EdgeClient>(server_address, std::move(config), std::move(options));
}

GrpcEdgeLink::~GrpcEdgeLink() {
  close();
}

void GrpcEdgeLink::send(KeyFrameUpload upload) {
  client_->uploadKeyFrame(std::move(upload));
}

void GrpcEdgeLink::setSliceHandler(SliceHandler handler) {
  MutexLock lock(handler_mutex_);
  handler_ = std::move(handler);
}

// The handlers run outside the link's locks (edge_link.h): a handler that calls back into the
// link, or takes its own locks, cannot deadlock against a send.
void GrpcEdgeLink::deliver(MapSlice slice) {
  SliceHandler handler;
  {
    MutexLock lock(handler_mutex_);
    handler = handler_;
  }
  if (handler) handler(std::move(slice));
}

void GrpcEdgeLink::setUploadDroppedHandler(UploadDroppedHandler handler) {
  MutexLock lock(dropped_mutex_);
  dropped_handler_ = std::move(handler);
}

void GrpcEdgeLink::reportDropped(std::uint64_t sequence, KeyFrameId keyframe) {
  UploadDroppedHandler handler;
  {
    MutexLock lock(dropped_mutex_);
    handler = dropped_handler_;
  }
  if (handler) handler(sequence, keyframe);
}

EdgeLinkCounters GrpcEdgeLink::counters() const {
  const EdgeClientCounters c = client_->counters();
  EdgeLinkCounters out;
  out.uplink_bytes = c.uplink_bytes;
  out.downlink_bytes = c.downlink_bytes;
  out.uploads_dropped = c.uploads_dropped;
  out.uploads_overflowed = c.uploads_overflowed;
  out.reconnects = c.reconnects;
  return out;
}

void GrpcEdgeLink::close() {
  client_->close();
}

}  // namespace edgeslam
