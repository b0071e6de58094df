#pragma once
// The gRPC handlers of the EdgeSlam service (server side): header and version checks, decoding,
// per-session ordering and accounting, slice streaming. Owned by EdgeServer.
#include <atomic>
#include <memory>

#include "edgeslam/v1/edgeslam.grpc.pb.h"
#include "wire/access_tokens.h"
#include "wire/edge_server.h"
#include "wire/session_registry.h"

namespace edgeslam {

class EdgeService final : public v1::EdgeSlam::Service {
 public:
  // `tokens` null: every client is let in without authorization metadata.
  EdgeService(SessionRegistry& registry, std::shared_ptr<EdgeSessionFactory> factory,
              const EdgeServerLimits& limits, std::shared_ptr<const AccessTokens> tokens = nullptr);

  // Makes every stream return at its next poll and refuses new calls.
  void stop() { stopping_.store(true); }

  grpc::Status OpenSession(grpc::ServerContext* context, const v1::OpenSessionRequest* request,
                           v1::OpenSessionReply* reply) override;
  grpc::Status CloseSession(grpc::ServerContext* context, const v1::CloseSessionRequest* request,
                            v1::CloseSessionReply* reply) override;
  grpc::Status UploadKeyFrame(grpc::ServerContext* context,
                              const v1::UploadKeyFrameRequest* request,
                              v1::UploadKeyFrameReply* reply) override;
  grpc::Status StreamSlices(grpc::ServerContext* context, const v1::StreamSlicesRequest* request,
                            grpc::ServerWriter<v1::MapSlice>* writer) override;
  grpc::Status Probe(grpc::ServerContext* context, const v1::ProbeRequest* request,
                     v1::ProbeReply* reply) override;
  grpc::Status OffloadFrame(grpc::ServerContext* context, const v1::OffloadFrameRequest* request,
                            v1::OffloadFrameReply* reply) override;

 private:
  // The caller's grant from its `authorization: Bearer TOKEN` metadata (nullptr without
  // tokens); UNAUTHENTICATED when it has none or an unknown one.
  grpc::Status authenticate(const grpc::ServerContext& context, const AccessGrant** grant) const;
  // The header's session, when it exists and belongs to the caller.
  grpc::Status findSession(const grpc::ServerContext& context, const v1::RequestHeader& header,
                           std::shared_ptr<ServerSession>* session) const;
  // ABORTED, and the session closed, when its back end failed (EdgeSessionBackend::failure()).
  grpc::Status endIfFailed(const ServerSession& session) const;
  // RESOURCE_EXHAUSTED when the session sends uploads or frames faster than its limit.
  grpc::Status admitUpload(ServerSession& session) const REQUIRES(session.backend_mutex);

  SessionRegistry& registry_;
  std::shared_ptr<EdgeSessionFactory> factory_;
  const EdgeServerLimits limits_;
  const std::shared_ptr<const AccessTokens> tokens_;
  std::atomic<bool> stopping_{false};
};

}  // namespace edgeslam
