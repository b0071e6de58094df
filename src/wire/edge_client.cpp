#include "wire/edge_client.h"

#include <fmt/format.h>
#include <grpcpp/grpcpp.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <deque>
#include <thread>

#include "edgeslam/v1/edgeslam.grpc.pb.h"
#include "util/mutex.h"
#include "wire/channel_options.h"
#include "wire/server_security.h"
#include "wire/wire_convert.h"

namespace edgeslam {
namespace {

using Clock = std::chrono::steady_clock;

std::chrono::system_clock::time_point deadlineIn(std::chrono::milliseconds timeout) {
  return std::chrono::system_clock::now() + timeout;
}

std::string describe(const grpc::Status& status) {
  return fmt::format("{} ({})", status.error_message(), static_cast<int>(status.error_code()));
}

// Failures that retrying cannot fix: the request itself is wrong for this server.
bool isPermanent(grpc::StatusCode code) {
  return code == grpc::StatusCode::INVALID_ARGUMENT ||
         code == grpc::StatusCode::RESOURCE_EXHAUSTED ||
         code == grpc::StatusCode::FAILED_PRECONDITION || code == grpc::StatusCode::UNIMPLEMENTED ||
         code == grpc::StatusCode::INTERNAL || code == grpc::StatusCode::UNAUTHENTICATED ||
         code == grpc::StatusCode::PERMISSION_DENIED;
}

std::shared_ptr<grpc::ChannelCredentials> channelCredentials(
    const EdgeClientCredentials& credentials) {
  if (credentials.tls_ca_pem.empty()) return grpc::InsecureChannelCredentials();
  grpc::SslCredentialsOptions tls;
  tls.pem_root_certs = credentials.tls_ca_pem;
  return grpc::SslCredentials(tls);
}

class Backoff {
 public:
  Backoff(std::chrono::milliseconds initial, std::chrono::milliseconds max)
      : initial_(initial), max_(std::max(max, initial)), next_(initial) {}
  std::chrono::milliseconds next() {
    const auto current = next_;
    next_ = std::min(max_, next_ * 2);
    return current;
  }
  void reset() { next_ = initial_; }

 private:
  std::chrono::milliseconds initial_, max_, next_;
};

}  // namespace

struct EdgeClient::Impl {
  Impl(const std::string& address, SessionConfig session_config, EdgeClientOptions client_options)
      : server_address(address),
        config(std::move(session_config)),
        options(std::move(client_options)) {
    options.upload_queue_capacity = std::max<std::size_t>(options.upload_queue_capacity, 1);
    encode_options.keypoint_response = options.send_keypoint_response;
    encode_options.omit_known_point_descriptors = options.omit_known_point_descriptors;
    channel = grpc::CreateCustomChannel(
        address, channelCredentials(options.credentials),
        clientChannelArguments(options.max_receive_message_bytes,
                               static_cast<int>(options.backoff_max.count())));
    stub = v1::EdgeSlam::NewStub(channel);
    if (!channel->WaitForConnected(deadlineIn(options.connect_timeout))) {
      throw EdgeClientError(
          fmt::format("edge server at '{}' is not reachable (no connection within "
                      "{} ms): is it running, and is the address right{}?",
                      address, options.connect_timeout.count(),
                      options.credentials.tls_ca_pem.empty()
                          ? ""
                          : ", and does its TLS certificate match the CA and the address"));
    }
    if (const grpc::Status status = openSession(options.open_session_timeout); !status.ok()) {
      throw EdgeClientError(
          fmt::format("edge server at '{}' refused the session: {}", address, describe(status)));
    }
    upload_thread = std::thread([this] { uploadLoop(); });
    if (options.on_slice) slice_thread = std::thread([this] { sliceLoop(); });
  }

  ~Impl() { close(); }

  // --- session ---------------------------------------------------------------------------------

  // Every call carries the client's token (when it has one).
  void authorize(grpc::ClientContext& context) const {
    if (!options.credentials.token.empty()) {
      context.AddMetadata(kAuthorizationMetadataKey, "Bearer " + options.credentials.token);
    }
  }

  v1::RequestHeader header() const {
    v1::RequestHeader h;
    h.set_protocol_version(kWireProtocolVersion);
    h.set_session_id(session_id.load());
    return h;
  }

  grpc::Status openSession(std::chrono::milliseconds timeout) {
    v1::OpenSessionRequest request;
    SessionConfig wanted = config;
    wanted.id_origin = id_origin.load() != 0 ? id_origin.load() : config.id_origin;
    toProto(wanted, &request);
    request.mutable_header()->set_protocol_version(kWireProtocolVersion);
    v1::OpenSessionReply reply;
    grpc::ClientContext context;
    authorize(context);
    context.set_deadline(deadlineIn(timeout));
    const grpc::Status status = stub->OpenSession(&context, request, &reply);
    if (!status.ok()) return status;
    if (reply.id_origin() < 1 || reply.id_origin() > 255 || reply.session_id() == 0) {
      return {grpc::StatusCode::INTERNAL,
              fmt::format("the server answered with session {:#x} and id origin {}",
                          reply.session_id(), reply.id_origin())};
    }
    session_id.store(reply.session_id());
    id_origin.store(static_cast<std::uint8_t>(reply.id_origin()));
    id_floor.store(reply.id_floor());
    uplink += request.ByteSizeLong();
    downlink += reply.ByteSizeLong();
    return status;
  }

  // Opens a new session after the server said it lost `lost_session`; only one thread does it.
  bool reopenSession(std::uint64_t lost_session, const std::string& reason)
      EXCLUDES(reopen_mutex, mutex) {
    MutexLock lock(reopen_mutex);
    if (session_id.load() != lost_session) return true;  // another thread already did it
    // Before the new session exists, so that every upload it takes is remembered; those the lost
    // session took are not in the new one's map.
    {
      MutexLock state(mutex);
      acknowledged_while_resyncing.clear();
    }
    resync_pending.store(true);
    const grpc::Status status = openSession(options.open_session_timeout);
    if (!status.ok()) {
      spdlog::warn("edge client: reopening the session failed: {}", describe(status));
      return false;
    }
    ++session_reopens;
    last_applied.store(0);  // the new session's slices start at 1
    spdlog::warn("edge client: session reopened ({}), id origin {}", reason, id_origin.load());
    notify({true, true, id_origin.load(), reason});
    return true;
  }

  // Which upload was given up on, for the owner's callback.
  struct DroppedUpload {
    std::uint64_t sequence = 0;
    KeyFrameId keyframe = kInvalidId;
  };

  static DroppedUpload identify(const KeyFrameUpload& upload) {
    return {upload.sequence, upload.keyframe.id};
  }

  // Outside the client's mutex: the owner may take its own locks (its map's) here.
  void reportDropped(const DroppedUpload& dropped) EXCLUDES(mutex) {
    if (!options.on_upload_dropped) return;
    try {
      options.on_upload_dropped(dropped.sequence, dropped.keyframe);
    } catch (const std::exception& e) {
      spdlog::error("edge client: upload-dropped callback threw for upload {}: {}",
                    dropped.sequence, e.what());
    }
  }

  void notify(const EdgeSessionEvent& event) {
    if (!options.on_session_event) return;
    try {
      options.on_session_event(event);
    } catch (const std::exception& e) {
      spdlog::error("edge client: session event callback threw: {}", e.what());
    }
  }

  // --- stopping --------------------------------------------------------------------------------

  // Sleeps up to `duration`, returning early (true) when the client is closing.
  bool sleepUnlessStopping(std::chrono::milliseconds duration) EXCLUDES(mutex) {
    MutexLock lock(mutex);
    return lock.waitFor(wake, duration, [&]() REQUIRES(mutex) { return stopping; });
  }

  bool isStopping() EXCLUDES(mutex) {
    MutexLock lock(mutex);
    return stopping;
  }

  void close() EXCLUDES(mutex) {
    {
      MutexLock lock(mutex);
      if (closed) return;
      closed = true;
      stopping = true;
      if (upload_context != nullptr) upload_context->TryCancel();
      if (stream_context != nullptr) stream_context->TryCancel();
    }
    wake.notify_all();
    if (upload_thread.joinable()) upload_thread.join();
    if (slice_thread.joinable()) slice_thread.join();
    {
      MutexLock lock(mutex);
      uploads_dropped += queue.size();
      queue.clear();
    }
    v1::CloseSessionRequest request;
    *request.mutable_header() = header();
    v1::CloseSessionReply reply;
    grpc::ClientContext context;
    authorize(context);
    context.set_deadline(deadlineIn(options.close_timeout));
    if (stub->CloseSession(&context, request, &reply).ok()) {
      uplink += request.ByteSizeLong();
      downlink += reply.ByteSizeLong();
    }
  }

  // --- uploads ---------------------------------------------------------------------------------

  std::uint64_t enqueue(KeyFrameUpload upload) EXCLUDES(mutex) {
    std::optional<DroppedUpload> overflowed;
    std::uint64_t sequence = 0;
    {
      MutexLock lock(mutex);
      if (upload.sequence == 0) upload.sequence = last_upload_sequence + 1;
      last_upload_sequence = std::max(last_upload_sequence, upload.sequence);
      sequence = upload.sequence;
      if (closed) {
        ++uploads_dropped;
        return sequence;
      }
      if (queue.size() >= options.upload_queue_capacity) {
        overflowed = identify(queue.front());
        queue.pop_front();
        ++uploads_dropped;
        ++uploads_overflowed;
      }
      queue.push_back(std::move(upload));
    }
    wake.notify_all();
    if (overflowed) {
      spdlog::debug("edge client: upload {} (keyframe {:#x}) pushed out of the full queue",
                    overflowed->sequence, overflowed->keyframe);
      reportDropped(*overflowed);
    }
    return sequence;
  }

  void uploadLoop() EXCLUDES(mutex) {
    Backoff backoff(options.backoff_initial, options.backoff_max);
    while (true) {
      KeyFrameUpload upload;
      DroppedUpload which;
      {
        MutexLock lock(mutex);
        lock.wait(wake, [&]() REQUIRES(mutex) { return stopping || !queue.empty(); });
        if (stopping) return;
        upload = std::move(queue.front());
        queue.pop_front();
        in_flight = true;
        in_flight_keyframe = upload.keyframe.id;
        which = identify(upload);
      }
      v1::UploadKeyFrameRequest request;
      try {
        compressKeyFrameImage(upload, options.keyframe_image);
        toProto(upload, request.mutable_upload(), encode_options);
        if (encode_options.omit_known_point_descriptors &&
            spdlog::should_log(spdlog::level::debug)) {
          WireEncodeOptions every_descriptor = encode_options;
          every_descriptor.omit_known_point_descriptors = false;
          const v1::KeyFrameFeatures& features = request.upload().keyframe().features();
          spdlog::debug(
              "edge client: upload {}: {} bytes ({} with every descriptor); {} keypoints, {} "
              "associations, {} new points, {} descriptors sent",
              upload.sequence, wireSize(request.upload()), wireSize(upload, every_descriptor),
              features.keypoints().count(), request.upload().keyframe().point_id_deltas_size(),
              upload.new_points.size(), features.descriptors().size() / 32);
        }
      } catch (const std::exception& e) {
        spdlog::error("edge client: upload {} cannot be encoded: {}", upload.sequence, e.what());
        finishUpload(Outcome::kRejected, which);
        continue;
      }
      sendWithRetry(request, which, backoff);
    }
  }

  enum class Outcome {
    kSent,
    kRejected,   // refused by the server or not encodable: reported to the owner
    kDiscarded,  // the client is closing
  };

  void finishUpload(Outcome outcome, const DroppedUpload& which) EXCLUDES(mutex) {
    // Reported before the upload counts as done, so that flushUploads() returning means the
    // owner has heard of it.
    if (outcome == Outcome::kRejected) reportDropped(which);
    MutexLock lock(mutex);
    in_flight = false;
    if (outcome == Outcome::kSent) {
      ++uploads_sent;
      if (resync_pending.load()) acknowledged_while_resyncing.push_back(which.keyframe);
    } else {
      ++uploads_dropped;
    }
    if (outcome == Outcome::kRejected) ++uploads_rejected;
    flushed.notify_all();
  }

  void sendWithRetry(v1::UploadKeyFrameRequest& request, const DroppedUpload& which,
                     Backoff& backoff) EXCLUDES(mutex) {
    while (true) {
      const std::uint64_t session = session_id.load();
      *request.mutable_header() = header();
      request.mutable_upload()->set_acknowledged_slice(
          std::max(request.upload().acknowledged_slice(), last_applied.load()));
      grpc::ClientContext context;
      authorize(context);
      context.set_deadline(deadlineIn(options.rpc_timeout));
      // While the channel reconnects the call waits (within its deadline) instead of failing at
      // once and sleeping a backoff: it goes out as soon as the server is back.
      context.set_wait_for_ready(true);
      bool discard = false;
      {
        MutexLock lock(mutex);
        discard = stopping;
        if (!discard) upload_context = &context;
      }
      // finishUpload takes the mutex itself: called under it, a close racing this upload hung.
      if (discard) return finishUpload(Outcome::kDiscarded, which);
      v1::UploadKeyFrameReply reply;
      const grpc::Status status = stub->UploadKeyFrame(&context, request, &reply);
      {
        MutexLock lock(mutex);
        upload_context = nullptr;
      }
      if (status.ok()) {
        uplink += request.ByteSizeLong();
        downlink += reply.ByteSizeLong();
        backoff.reset();
        reconnecting.store(false);
        return finishUpload(Outcome::kSent, which);
      }
      if (isStopping()) return finishUpload(Outcome::kDiscarded, which);
      if (status.error_code() == grpc::StatusCode::ABORTED) {
        spdlog::error("edge client: {}", status.error_message());
      }
      if (status.error_code() == grpc::StatusCode::NOT_FOUND ||
          status.error_code() == grpc::StatusCode::ABORTED) {
        reconnecting.store(true);
        if (reopenSession(session, "keyframe upload: " + status.error_message())) continue;
      } else if (isPermanent(status.error_code())) {
        spdlog::error("edge client: upload {} rejected: {}", request.upload().sequence(),
                      describe(status));
        return finishUpload(Outcome::kRejected, which);
      }
      // Anything else (unreachable, deadline exceeded: perhaps after the server had it) is
      // retried; the server passes a retried sequence on once only.
      reconnecting.store(true);
      ++upload_retries;
      if (sleepUnlessStopping(backoff.next())) return finishUpload(Outcome::kDiscarded, which);
    }
  }

  bool flush(std::chrono::milliseconds timeout) EXCLUDES(mutex) {
    MutexLock lock(mutex);
    return lock.waitFor(flushed, timeout,
                        [&]() REQUIRES(mutex) { return queue.empty() && !in_flight; });
  }

  // --- slices ----------------------------------------------------------------------------------

  void sliceLoop() EXCLUDES(mutex) {
    Backoff backoff(options.backoff_initial, options.backoff_max);
    bool first = true;
    while (!isStopping()) {
      const std::uint64_t session = session_id.load();
      v1::StreamSlicesRequest request;
      *request.mutable_header() = header();
      request.set_from_sequence(last_applied.load() + 1);
      request.set_want_full_resync(resync_pending.load());
      grpc::ClientContext context;
      authorize(context);
      {
        MutexLock lock(mutex);
        if (stopping) return;
        stream_context = &context;
      }
      if (!first) ++reconnects;
      first = false;
      auto reader = stub->StreamSlices(&context, request);
      v1::MapSlice message;
      bool received = false;
      while (reader->Read(&message)) {
        if (!received) uplink += request.ByteSizeLong();
        received = true;
        backoff.reset();
        reconnecting.store(false);
        downlink += message.ByteSizeLong();
        deliver(message);
      }
      const grpc::Status status = reader->Finish();
      {
        MutexLock lock(mutex);
        stream_context = nullptr;
      }
      if (isStopping()) return;
      const grpc::StatusCode code = status.error_code();
      // The stream breaks at once when the server goes: uploads would only notice at their
      // deadline.
      if (code == grpc::StatusCode::UNAVAILABLE || code == grpc::StatusCode::NOT_FOUND ||
          code == grpc::StatusCode::ABORTED) {
        reconnecting.store(true);
      }
      if (code == grpc::StatusCode::ABORTED)
        spdlog::error("edge client: {}", status.error_message());
      if (code == grpc::StatusCode::NOT_FOUND || code == grpc::StatusCode::ABORTED) {
        if (reopenSession(session, "slice stream: " + status.error_message())) continue;
      } else if (code == grpc::StatusCode::OUT_OF_RANGE) {
        spdlog::warn("edge client: slice stream: {}", status.error_message());
        if (!resync_pending.exchange(true)) {
          notify({false, true, id_origin.load(), status.error_message()});
        }
        continue;
      } else if (!status.ok()) {
        spdlog::debug("edge client: slice stream ended: {}", describe(status));
      }
      if (sleepUnlessStopping(backoff.next())) return;
    }
  }

  void deliver(const v1::MapSlice& message) EXCLUDES(mutex) {
    if (message.sequence() <= last_applied.load()) return;  // already applied before a reconnect
    MapSlice slice;
    try {
      slice = fromProto(message);
    } catch (const WireError& e) {
      spdlog::error("edge client: malformed slice skipped: {}", e.what());
      last_applied.store(message.sequence());
      return;
    }
    const std::uint64_t sequence = slice.sequence;
    const bool full_resync = slice.full_resync;
    try {
      options.on_slice(std::move(slice));
    } catch (const std::exception& e) {
      spdlog::error("edge client: slice {} callback threw: {}", sequence, e.what());
    }
    ++slices_received;
    last_applied.store(sequence);
    if (full_resync) {
      resync_pending.store(false);
      MutexLock lock(mutex);
      acknowledged_while_resyncing.clear();
    }
  }

  // --- data ------------------------------------------------------------------------------------

  const std::string server_address;
  const SessionConfig config;
  EdgeClientOptions options;
  WireEncodeOptions encode_options;
  std::shared_ptr<grpc::Channel> channel;
  std::unique_ptr<v1::EdgeSlam::Stub> stub;

  std::atomic<std::uint64_t> session_id{0};
  std::atomic<std::uint8_t> id_origin{0};
  std::atomic<std::uint64_t> id_floor{0};
  std::atomic<bool> reconnecting{false};
  Mutex reopen_mutex;
  std::atomic<std::uint64_t> last_applied{0};
  std::atomic<bool> resync_pending{false};

  mutable Mutex mutex;
  std::condition_variable wake;
  std::condition_variable flushed;
  bool stopping GUARDED_BY(mutex) = false;
  bool closed GUARDED_BY(mutex) = false;
  std::deque<KeyFrameUpload> queue GUARDED_BY(mutex);
  bool in_flight GUARDED_BY(mutex) = false;
  KeyFrameId in_flight_keyframe GUARDED_BY(mutex) = kInvalidId;
  // Keyframes the session took while a full resync was pending: perhaps after the resync's
  // snapshot of the edge's map, so not listed there, yet not lost.
  std::vector<KeyFrameId> acknowledged_while_resyncing GUARDED_BY(mutex);
  std::uint64_t last_upload_sequence GUARDED_BY(mutex) = 0;
  grpc::ClientContext* upload_context GUARDED_BY(mutex) = nullptr;
  grpc::ClientContext* stream_context GUARDED_BY(mutex) = nullptr;
  std::uint64_t uploads_sent GUARDED_BY(mutex) = 0;
  std::uint64_t uploads_dropped GUARDED_BY(mutex) = 0;
  std::uint64_t uploads_overflowed GUARDED_BY(mutex) = 0;
  std::uint64_t uploads_rejected GUARDED_BY(mutex) = 0;

  std::atomic<std::uint64_t> uplink{0};
  std::atomic<std::uint64_t> downlink{0};
  std::atomic<std::uint64_t> upload_retries{0};
  std::atomic<std::uint64_t> slices_received{0};
  std::atomic<std::uint64_t> reconnects{0};
  std::atomic<std::uint64_t> session_reopens{0};

  std::thread upload_thread;
  std::thread slice_thread;
};

EdgeClient::EdgeClient(const std::string& server_address, SessionConfig config,
                       EdgeClientOptions options)
    : impl_(std::make_unique<Impl>(server_address, std::move(config), std::move(options))) {}

EdgeClient::~EdgeClient() {
  close();
}

std::uint64_t EdgeClient::sessionId() const {
  return impl_->session_id.load();
}

std::uint8_t EdgeClient::idOrigin() const {
  return impl_->id_origin.load();
}

std::uint64_t EdgeClient::idFloor() const {
  return impl_->id_floor.load();
}

bool EdgeClient::reconnecting() const {
  return impl_->reconnecting.load();
}

bool EdgeClient::connected() const {
  return impl_->channel->GetState(false) == GRPC_CHANNEL_READY;
}

std::vector<KeyFrameId> EdgeClient::pendingUploadKeyFrames() const {
  MutexLock lock(impl_->mutex);
  std::vector<KeyFrameId> out = impl_->acknowledged_while_resyncing;
  if (impl_->in_flight) out.push_back(impl_->in_flight_keyframe);
  for (const KeyFrameUpload& upload : impl_->queue) out.push_back(upload.keyframe.id);
  return out;
}

std::uint64_t EdgeClient::uploadKeyFrame(KeyFrameUpload upload) {
  return impl_->enqueue(std::move(upload));
}

bool EdgeClient::flushUploads(std::chrono::milliseconds timeout) {
  return impl_->flush(timeout);
}

std::size_t EdgeClient::pendingUploads() const {
  MutexLock lock(impl_->mutex);
  return impl_->queue.size() + (impl_->in_flight ? 1 : 0);
}

std::optional<ProbeResult> EdgeClient::probe(std::size_t payload_bytes, std::size_t reply_bytes,
                                             std::optional<std::chrono::milliseconds> timeout) {
  v1::ProbeRequest request;
  *request.mutable_header() = impl_->header();
  std::string* payload = request.mutable_payload();
  payload->resize(payload_bytes);
  std::uint32_t state = 0x2545f491u;
  for (char& c : *payload) {
    state = state * 1664525u + 1013904223u;
    c = static_cast<char>(state >> 24);
  }
  request.set_reply_bytes(reply_bytes);
  v1::ProbeReply reply;
  grpc::ClientContext context;
  impl_->authorize(context);
  context.set_deadline(deadlineIn(timeout.value_or(impl_->options.rpc_timeout)));
  const auto start = Clock::now();
  const grpc::Status status = impl_->stub->Probe(&context, request, &reply);
  const auto end = Clock::now();
  if (!status.ok()) {
    if (isPermanent(status.error_code())) {
      throw EdgeClientError(fmt::format("probe rejected by the edge server: {}", describe(status)));
    }
    return std::nullopt;
  }
  ProbeResult result;
  result.round_trip_ms = std::chrono::duration<double, std::milli>(end - start).count();
  result.sent_bytes = request.ByteSizeLong();
  result.received_bytes = reply.ByteSizeLong();
  result.server_time_ns = reply.server_time_ns();
  impl_->uplink += result.sent_bytes;
  impl_->downlink += result.received_bytes;
  return result;
}

std::optional<OffloadResult> EdgeClient::offloadFrame(const OffloadFrame& frame) {
  v1::OffloadFrameRequest request;
  toProto(frame, &request);
  for (int attempt = 0; attempt < 2; ++attempt) {
    const std::uint64_t session = impl_->session_id.load();
    *request.mutable_header() = impl_->header();
    v1::OffloadFrameReply reply;
    grpc::ClientContext context;
    impl_->authorize(context);
    context.set_deadline(deadlineIn(impl_->options.rpc_timeout));
    const grpc::Status status = impl_->stub->OffloadFrame(&context, request, &reply);
    if (status.ok()) {
      impl_->uplink += request.ByteSizeLong();
      impl_->downlink += reply.ByteSizeLong();
      try {
        return fromProto(reply);
      } catch (const WireError& e) {
        throw EdgeClientError(fmt::format("malformed offload reply: {}", e.what()));
      }
    }
    const bool session_gone = status.error_code() == grpc::StatusCode::NOT_FOUND ||
                              status.error_code() == grpc::StatusCode::ABORTED;
    if (status.error_code() == grpc::StatusCode::ABORTED) {
      spdlog::error("edge client: {}", status.error_message());
    }
    if (session_gone && attempt == 0 &&
        impl_->reopenSession(session, "frame offload: " + status.error_message())) {
      continue;
    }
    if (isPermanent(status.error_code()) || session_gone) {
      throw EdgeClientError(fmt::format("frame {} rejected by the edge server: {}",
                                        frame.frame_index, describe(status)));
    }
    return std::nullopt;
  }
  return std::nullopt;
}

std::uint64_t EdgeClient::lastAppliedSlice() const {
  return impl_->last_applied.load();
}

bool EdgeClient::fullResyncPending() const {
  return impl_->resync_pending.load();
}

EdgeClientCounters EdgeClient::counters() const {
  EdgeClientCounters c;
  c.uplink_bytes = impl_->uplink.load();
  c.downlink_bytes = impl_->downlink.load();
  {
    MutexLock lock(impl_->mutex);
    c.uploads_sent = impl_->uploads_sent;
    c.uploads_dropped = impl_->uploads_dropped;
    c.uploads_overflowed = impl_->uploads_overflowed;
    c.uploads_rejected = impl_->uploads_rejected;
  }
  c.upload_retries = impl_->upload_retries.load();
  c.slices_received = impl_->slices_received.load();
  c.reconnects = impl_->reconnects.load();
  c.session_reopens = impl_->session_reopens.load();
  return c;
}

void EdgeClient::close() {
  impl_->close();
}

}  // namespace edgeslam
