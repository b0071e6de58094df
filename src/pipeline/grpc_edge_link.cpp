#include "pipeline/grpc_edge_link.h"

#include <spdlog/spdlog.h>

namespace edgeslam {

GrpcEdgeLink::GrpcEdgeLink(const std::string& server_address, SessionConfig config,
                           EdgeClientOptions options) {
  options.on_slice = [this](MapSlice slice) { deliver(std::move(slice)); };
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
  std::lock_guard lock(handler_mutex_);
  handler_ = std::move(handler);
}

void GrpcEdgeLink::deliver(MapSlice slice) {
  std::lock_guard lock(handler_mutex_);
  if (handler_) handler_(std::move(slice));
}

EdgeLinkCounters GrpcEdgeLink::counters() const {
  const EdgeClientCounters c = client_->counters();
  return {c.uplink_bytes, c.downlink_bytes, c.uploads_dropped, c.reconnects};
}

void GrpcEdgeLink::close() {
  client_->close();
}

}  // namespace edgeslam
