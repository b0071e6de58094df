#pragma once
// The mobile side of the wire: opens a session on the edge server, uploads keyframes without ever
// blocking the caller, streams map slices back to a callback, and survives the server going away
// (reconnects with backoff, resumes the slice stream where it stopped, reopens a lost session).
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "map/map_records.h"
#include "semantic/keyframe_image.h"
#include "wire/wire_types.h"

namespace edgeslam {

// The server is unreachable at connection time, refused the session, or rejected a request.
class EdgeClientError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Something the client's owner must react to, reported from the client's threads.
struct EdgeSessionEvent {
  // The server had lost the session (restart, idle timeout) and a new one was opened; ids made
  // from now on must use `id_origin` (the old origin is asked for and usually granted).
  bool reopened = false;
  // The client's map can no longer be kept in step by slices: drop it when the next slice with
  // full_resync arrives (the edge has been asked for one).
  bool full_resync_needed = false;
  std::uint8_t id_origin = 0;
  std::string reason;
};

// How the client proves itself to the server and checks the server (server_security.h).
struct EdgeClientCredentials {
  std::string tls_ca_pem;  // non-empty: TLS, the server's certificate checked against this CA
  std::string token;       // non-empty: sent with every call as `authorization: Bearer TOKEN`
};

struct EdgeClientOptions {
  EdgeClientCredentials credentials;
  std::chrono::milliseconds connect_timeout{3000};
  std::chrono::milliseconds rpc_timeout{5000};
  // Opening a session that names a stored map waits for the edge to load it: about 1.5 s per
  // thousand keyframes on this machine kind (4.4 s for 3000 timed out the 3 s it had before).
  std::chrono::milliseconds open_session_timeout{120000};
  std::chrono::milliseconds close_timeout{500};
  std::size_t upload_queue_capacity = 8;  // waiting uploads; the oldest is dropped beyond
  std::chrono::milliseconds backoff_initial{100};
  std::chrono::milliseconds backoff_max{2000};
  std::size_t max_receive_message_bytes = 64u << 20;
  bool send_keypoint_response = false;
  // Uploads leave out the descriptors of keypoints whose point the edge already has (32 bytes
  // each, about 40 % of a monocular upload); the edge takes the point's descriptor instead.
  bool omit_known_point_descriptors = true;
  // How a keyframe's image (when the upload carries one) is compressed before it is sent.
  KeyFrameImageOptions keyframe_image;
  // Called on the slice reader thread, in sequence order, one slice at a time. Leave empty for a
  // client that does not stream slices (probing, offload mode).
  std::function<void(MapSlice)> on_slice;
  std::function<void(const EdgeSessionEvent&)> on_session_event;
  // Called once for every upload the client gives up on while the session runs: pushed out of
  // the full queue (on the thread calling uploadKeyFrame), refused by the server or not encodable
  // (on the upload thread, before the next upload is sent and before flushUploads sees it done).
  // Never under the client's own lock. Not called for uploads close() discards: the session is
  // over. An upload whose deadline passed after its bytes went out is not dropped but retried;
  // the server passes a retry of an upload it already has on once only.
  std::function<void(std::uint64_t sequence, KeyFrameId keyframe)> on_upload_dropped;
};

struct EdgeClientCounters {
  std::uint64_t uplink_bytes = 0;    // serialized bytes of requests the server received
  std::uint64_t downlink_bytes = 0;  // serialized bytes of replies and slices received
  std::uint64_t uploads_sent = 0;
  // Pushed out of the full queue, rejected by the server, not encodable, or discarded by close().
  std::uint64_t uploads_dropped = 0;
  std::uint64_t uploads_overflowed = 0;  // of those, pushed out of the full queue
  std::uint64_t uploads_rejected = 0;    // of those, refused by the server (malformed, too big)
  std::uint64_t upload_retries = 0;
  std::uint64_t slices_received = 0;
  std::uint64_t reconnects = 0;  // slice streams re-established after a failure
  std::uint64_t session_reopens = 0;
};

struct ProbeResult {
  double round_trip_ms = 0.0;
  std::size_t sent_bytes = 0;      // serialized request size
  std::size_t received_bytes = 0;  // serialized reply size
  std::uint64_t server_time_ns = 0;
};

class EdgeClient {
 public:
  // Connects and opens a session (config.id_origin = the origin wished for, 0 = any). Throws
  // EdgeClientError naming the address when the server cannot be reached within
  // options.connect_timeout or refuses the session.
  EdgeClient(const std::string& server_address, SessionConfig config,
             EdgeClientOptions options = {});
  ~EdgeClient();  // close()
  EdgeClient(const EdgeClient&) = delete;
  EdgeClient& operator=(const EdgeClient&) = delete;

  std::uint64_t sessionId() const;
  std::uint8_t idOrigin() const;  // top byte for every id this client makes
  // Ids of this origin the session's map already held when it opened (a map the edge loaded from
  // its store): make ids above it. 0 = none.
  std::uint64_t idFloor() const;
  // The last upload attempt failed for want of the server (unreachable, or its session lost and
  // not reopened yet); false again once an upload goes through.
  bool reconnecting() const;
  // The channel to the server is connected now (false while the server is down or being reached
  // again). A probe that failed while this is false measured an outage, not the link.
  bool connected() const;
  // Keyframes on their way to the session's map: uploads queued or being sent, and those the
  // session acknowledged while a full resync was pending (the resync's slice may have been taken
  // before they arrived). A keyframe a full resync does not list and this does not name is lost.
  std::vector<KeyFrameId> pendingUploadKeyFrames() const;

  // Queues a keyframe and returns at once with its sequence (the caller's when non-zero, else the
  // next one). acknowledged_slice is filled in with the last slice applied. A worker sends the
  // queue in order, retrying with backoff while the server is unreachable.
  std::uint64_t uploadKeyFrame(KeyFrameUpload upload);
  // Waits until every queued upload was sent or dropped; false on timeout.
  bool flushUploads(std::chrono::milliseconds timeout);
  std::size_t pendingUploads() const;

  // Round trip of `payload_bytes` up and `reply_bytes` down; nullopt when the server does not
  // answer within `timeout` (default: the RPC timeout).
  std::optional<ProbeResult> probe(std::size_t payload_bytes, std::size_t reply_bytes,
                                   std::optional<std::chrono::milliseconds> timeout = std::nullopt);

  // Offload mode: sends a whole frame and waits for its pose. nullopt when the server is
  // unreachable; throws EdgeClientError when the server rejects the frame.
  std::optional<OffloadResult> offloadFrame(const OffloadFrame& frame);

  std::uint64_t lastAppliedSlice() const;
  bool fullResyncPending() const;
  EdgeClientCounters counters() const;

  // Stops the threads, tells the server (best effort, within options.close_timeout) and returns;
  // uploads still queued are discarded. Idempotent, never hangs.
  void close();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace edgeslam
