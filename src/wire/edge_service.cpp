#include "wire/edge_service.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>

#include "wire/received_image_check.h"
#include "wire/wire_convert.h"

namespace edgeslam {
namespace {

grpc::Status checkVersion(const v1::RequestHeader& header) {
  if (header.protocol_version() == kWireProtocolVersion) return grpc::Status::OK;
  return {grpc::StatusCode::FAILED_PRECONDITION,
          fmt::format("protocol version {} is not supported: this edge server speaks edgeslam.v1 "
                      "protocol version {}{}",
                      header.protocol_version(), kWireProtocolVersion,
                      header.protocol_version() == 0 ? " (the request carries no version)" : "")};
}

grpc::Status invalid(const std::exception& e) {
  return {grpc::StatusCode::INVALID_ARGUMENT, e.what()};
}

grpc::Status internal(const char* what, const std::exception& e) {
  spdlog::error("edge server: {} failed: {}", what, e.what());
  return {grpc::StatusCode::INTERNAL, fmt::format("{} failed on the edge: {}", what, e.what())};
}

std::uint64_t steadyNowNs() {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(
                                        std::chrono::steady_clock::now().time_since_epoch())
                                        .count());
}

// Counts one unary call's bytes in its session and marks the session active.
struct CallAccounting {
  CallAccounting(ServerSession* s, const google::protobuf::MessageLite& request,
                 const google::protobuf::MessageLite& reply)
      : session(s), reply_message(reply) {
    if (session == nullptr) return;
    session->touch();
    session->uplink_bytes += request.ByteSizeLong();
  }
  ~CallAccounting() {
    if (session == nullptr) return;
    session->downlink_bytes += reply_message.ByteSizeLong();
    session->touch();
  }
  CallAccounting(const CallAccounting&) = delete;
  CallAccounting& operator=(const CallAccounting&) = delete;
  ServerSession* session;
  const google::protobuf::MessageLite& reply_message;
};

}  // namespace

EdgeService::EdgeService(SessionRegistry& registry, std::shared_ptr<EdgeSessionFactory> factory,
                         const EdgeServerLimits& limits, std::shared_ptr<const AccessTokens> tokens)
    : registry_(registry),
      factory_(std::move(factory)),
      limits_(limits),
      tokens_(std::move(tokens)) {}

grpc::Status EdgeService::authenticate(const grpc::ServerContext& context,
                                       const AccessGrant** grant) const {
  *grant = nullptr;
  if (tokens_ == nullptr) return grpc::Status::OK;
  const auto& metadata = context.client_metadata();
  const auto found = metadata.find(kAuthorizationMetadataKey);
  if (found == metadata.end()) {
    return {grpc::StatusCode::UNAUTHENTICATED,
            "this edge server wants a client token (authorization: Bearer TOKEN; edgeslam "
            "client --token or EDGESLAM_TOKEN)"};
  }
  const std::string_view value(found->second.data(), found->second.size());
  *grant = tokens_->find(bearerToken(value));
  if (*grant == nullptr) {
    return {grpc::StatusCode::UNAUTHENTICATED, "the client token is not known to this edge server"};
  }
  return grpc::Status::OK;
}

grpc::Status EdgeService::admitUpload(ServerSession& session) const {
  if (session.upload_rate.admit(limits_.max_uploads_per_second, std::chrono::steady_clock::now())) {
    return grpc::Status::OK;
  }
  return {grpc::StatusCode::RESOURCE_EXHAUSTED,
          fmt::format("session {:#x} sends more than {:g} uploads and frames a second",
                      session.config.session_id, limits_.max_uploads_per_second)};
}

grpc::Status EdgeService::findSession(const grpc::ServerContext& context,
                                      const v1::RequestHeader& header,
                                      std::shared_ptr<ServerSession>* session) const {
  if (grpc::Status status = checkVersion(header); !status.ok()) return status;
  const AccessGrant* grant = nullptr;
  if (grpc::Status status = authenticate(context, &grant); !status.ok()) return status;
  if (stopping_.load()) return {grpc::StatusCode::UNAVAILABLE, "the edge server is shutting down"};
  *session = registry_.find(header.session_id());
  if (*session == nullptr) {
    return {grpc::StatusCode::NOT_FOUND,
            fmt::format("session {:#x} is unknown to this edge server (closed, idle too long, or "
                        "the server restarted): open a new session",
                        header.session_id())};
  }
  if (grant != nullptr && (*session)->owner != grant->label) {
    session->reset();
    return {grpc::StatusCode::PERMISSION_DENIED,
            fmt::format("session {:#x} belongs to another client", header.session_id())};
  }
  if (grpc::Status status = endIfFailed(**session); !status.ok()) {
    session->reset();
    return status;
  }
  return grpc::Status::OK;
}

grpc::Status EdgeService::endIfFailed(const ServerSession& session) const {
  const std::optional<std::string> cause = session.backend->failure();
  if (!cause) return grpc::Status::OK;
  const std::uint64_t id = session.config.session_id;
  // Only this session ends: the server and every other session go on.
  if (registry_.closeFailed(id)) {
    spdlog::error("edge server: session {:#x} ('{}') ended: {}", id, session.config.client_name,
                  *cause);
  }
  return {grpc::StatusCode::ABORTED,
          fmt::format("session {:#x} ended on the edge: {}; open a new session", id, *cause)};
}

grpc::Status EdgeService::OpenSession(grpc::ServerContext* context,
                                      const v1::OpenSessionRequest* request,
                                      v1::OpenSessionReply* reply) {
  if (grpc::Status status = checkVersion(request->header()); !status.ok()) return status;
  const AccessGrant* grant = nullptr;
  if (grpc::Status status = authenticate(*context, &grant); !status.ok()) return status;
  if (stopping_.load()) return {grpc::StatusCode::UNAVAILABLE, "the edge server is shutting down"};
  SessionConfig config;
  try {
    config = fromProto(*request);
  } catch (const WireError& e) {
    return invalid(e);
  }
  // The map the session names (`--map`); a balancer in front may carry it as metadata instead.
  std::string map = config.map_name.empty() ? kDefaultMapName : config.map_name;
  if (const auto found = context->client_metadata().find(kMapMetadataKey);
      config.map_name.empty() && found != context->client_metadata().end()) {
    map.assign(found->second.data(), found->second.size());
  }
  if (grant != nullptr && !grant->permitsMap(map)) {
    return {grpc::StatusCode::PERMISSION_DENIED,
            fmt::format("this client token does not give access to map '{}'", map)};
  }
  SessionOwner owner;
  if (grant != nullptr) owner = {grant->label, limits_.max_sessions_per_client};
  std::shared_ptr<ServerSession> session;
  try {
    session = registry_.open(std::move(config), *factory_, owner);
  } catch (const SessionRegistryFull& e) {
    return {grpc::StatusCode::RESOURCE_EXHAUSTED, e.what()};
  } catch (const std::invalid_argument& e) {
    return invalid(e);
  } catch (const std::exception& e) {
    return internal("opening the session", e);
  }
  reply->set_session_id(session->config.session_id);
  reply->set_id_origin(session->config.id_origin);
  reply->set_protocol_version(kWireProtocolVersion);
  reply->set_max_message_bytes(limits_.max_message_bytes);
  {
    MutexLock lock(session->backend_mutex);
    reply->set_id_floor(session->backend->idFloor());
  }
  session->uplink_bytes += request->ByteSizeLong();
  session->downlink_bytes += reply->ByteSizeLong();
  spdlog::info("edge server: session {:#x} opened for '{}' ({}, {}), id origin {}",
               session->config.session_id, session->config.client_name,
               toString(session->config.sensor), session->config.camera.describe(),
               session->config.id_origin);
  return grpc::Status::OK;
}

grpc::Status EdgeService::CloseSession(grpc::ServerContext* context,
                                       const v1::CloseSessionRequest* request,
                                       v1::CloseSessionReply* reply) {
  std::shared_ptr<ServerSession> session;
  if (grpc::Status status = findSession(*context, request->header(), &session); !status.ok()) {
    return status;
  }
  session->uplink_bytes += request->ByteSizeLong();
  reply->set_uplink_bytes(session->uplink_bytes.load());
  reply->set_downlink_bytes(session->downlink_bytes.load() + reply->ByteSizeLong());
  registry_.close(session->config.session_id);
  spdlog::info("edge server: session {:#x} closed by its client", session->config.session_id);
  return grpc::Status::OK;
}

grpc::Status EdgeService::UploadKeyFrame(grpc::ServerContext* context,
                                         const v1::UploadKeyFrameRequest* request,
                                         v1::UploadKeyFrameReply* reply) {
  std::shared_ptr<ServerSession> session;
  if (grpc::Status status = findSession(*context, request->header(), &session); !status.ok()) {
    return status;
  }
  CallAccounting accounting(session.get(), *request, *reply);
  KeyFrameUpload upload;
  try {
    if (!request->has_upload()) throw WireError("the request carries no upload");
    upload = fromProto(request->upload());
    checkKeyFrameImage(upload, session->config.camera);
  } catch (const WireError& e) {
    return invalid(e);
  }
  const std::uint64_t sequence = upload.sequence;
  session->slices.acknowledge(upload.acknowledged_slice);
  reply->set_sequence(sequence);
  MutexLock lock(session->backend_mutex);
  if (sequence <= session->last_upload_sequence) {
    ++session->duplicate_uploads;
    reply->set_duplicate(true);
    return grpc::Status::OK;
  }
  if (grpc::Status status = admitUpload(*session); !status.ok()) return status;
  // Gaps after the session's first upload (a reopened session continues the client's count).
  if (session->last_upload_sequence != 0) {
    session->missing_uploads += sequence - session->last_upload_sequence - 1;
  }
  session->last_upload_sequence = sequence;
  try {
    session->backend->onKeyFrame(std::move(upload));
  } catch (const std::invalid_argument& e) {
    return invalid(e);  // the upload passed the wire checks but the backend cannot use it
  } catch (const std::exception& e) {
    return internal("keyframe upload", e);
  }
  ++session->keyframes;
  return grpc::Status::OK;
}

grpc::Status EdgeService::StreamSlices(grpc::ServerContext* context,
                                       const v1::StreamSlicesRequest* request,
                                       grpc::ServerWriter<v1::MapSlice>* writer) {
  std::shared_ptr<ServerSession> session;
  if (grpc::Status status = findSession(*context, request->header(), &session); !status.ok()) {
    return status;
  }
  session->uplink_bytes += request->ByteSizeLong();
  ++session->active_streams;
  struct StreamEnd {
    ServerSession& s;
    ~StreamEnd() {
      s.touch();
      --s.active_streams;
    }
  } stream_end{*session};

  std::uint64_t next = std::max<std::uint64_t>(request->from_sequence(), 1);
  // While resynchronising, dropped slices do not matter: the client drops its map anyway.
  bool resyncing = request->want_full_resync();
  if (resyncing) {
    next = session->slices.firstAvailable();
    MutexLock lock(session->backend_mutex);
    try {
      session->backend->onFullResyncRequested();
    } catch (const std::exception& e) {
      return internal("full resync", e);
    }
  } else {
    session->slices.acknowledge(next - 1);
  }
  while (true) {
    if (stopping_.load())
      return {grpc::StatusCode::UNAVAILABLE, "the edge server is shutting down"};
    if (context->IsCancelled()) return grpc::Status::CANCELLED;
    const SliceQueue::WaitResult result = session->slices.waitFrom(next, limits_.stream_poll);
    switch (result.status) {
      case SliceQueue::WaitStatus::kTimeout:
        if (grpc::Status status = endIfFailed(*session); !status.ok()) return status;
        session->touch();
        continue;
      case SliceQueue::WaitStatus::kClosed:
        if (stopping_.load()) {
          return {grpc::StatusCode::UNAVAILABLE, "the edge server is shutting down"};
        }
        return {grpc::StatusCode::NOT_FOUND,
                fmt::format("session {:#x} was closed", session->config.session_id)};
      case SliceQueue::WaitStatus::kGap:
        if (resyncing) {
          next = session->slices.firstAvailable();
          continue;
        }
        return {grpc::StatusCode::OUT_OF_RANGE,
                fmt::format("slices from {} on were dropped before the client acknowledged them: "
                            "ask for a full resync",
                            next)};
      case SliceQueue::WaitStatus::kBeyondEnd:
        return {grpc::StatusCode::OUT_OF_RANGE,
                fmt::format("slice {} was asked for, but this session has made only {}", next,
                            session->slices.lastPushed())};
      case SliceQueue::WaitStatus::kSlice:
        break;
    }
    if (!writer->Write(*result.slice)) return grpc::Status::CANCELLED;  // the client went away
    session->downlink_bytes += result.bytes;
    ++session->slices_sent;
    next = result.slice->sequence() + 1;
    if (result.slice->full_resync()) resyncing = false;
  }
}

grpc::Status EdgeService::Probe(grpc::ServerContext* context, const v1::ProbeRequest* request,
                                v1::ProbeReply* reply) {
  if (grpc::Status status = checkVersion(request->header()); !status.ok()) return status;
  const AccessGrant* grant = nullptr;
  if (grpc::Status status = authenticate(*context, &grant); !status.ok()) return status;
  if (request->reply_bytes() > limits_.max_probe_reply_bytes) {
    return {grpc::StatusCode::INVALID_ARGUMENT,
            fmt::format("probe reply of {} bytes asked; at most {}", request->reply_bytes(),
                        limits_.max_probe_reply_bytes)};
  }
  std::shared_ptr<ServerSession> session;
  if (request->header().session_id() != 0) session = registry_.find(request->header().session_id());
  if (session != nullptr && grant != nullptr && session->owner != grant->label) session.reset();
  CallAccounting accounting(session.get(), *request, *reply);
  // Incompressible filler, so a compressing link cannot shortcut the measurement.
  std::string* payload = reply->mutable_payload();
  payload->resize(request->reply_bytes());
  std::uint32_t state = 0x9e3779b9u;
  for (char& c : *payload) {
    state = state * 1664525u + 1013904223u;
    c = static_cast<char>(state >> 24);
  }
  reply->set_server_time_ns(steadyNowNs());
  return grpc::Status::OK;
}

grpc::Status EdgeService::OffloadFrame(grpc::ServerContext* context,
                                       const v1::OffloadFrameRequest* request,
                                       v1::OffloadFrameReply* reply) {
  std::shared_ptr<ServerSession> session;
  if (grpc::Status status = findSession(*context, request->header(), &session); !status.ok()) {
    return status;
  }
  CallAccounting accounting(session.get(), *request, *reply);
  edgeslam::OffloadFrame frame;
  try {
    frame = fromProto(*request);
    checkOffloadedImages(frame, session->config.camera);
  } catch (const WireError& e) {
    return invalid(e);
  }
  std::optional<OffloadResult> result;
  const auto start = std::chrono::steady_clock::now();
  {
    MutexLock lock(session->backend_mutex);
    if (grpc::Status status = admitUpload(*session); !status.ok()) return status;
    try {
      result = session->backend->onFrame(std::move(frame));
    } catch (const std::invalid_argument& e) {
      return invalid(e);
    } catch (const std::exception& e) {
      return internal("frame offload", e);
    }
  }
  if (!result) {
    return {grpc::StatusCode::UNIMPLEMENTED,
            "this edge server's sessions do not track whole frames (offload mode)"};
  }
  if (result->server_ms == 0.0) {
    result->server_ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  }
  ++session->frames;
  toProto(*result, reply);
  return grpc::Status::OK;
}

}  // namespace edgeslam
