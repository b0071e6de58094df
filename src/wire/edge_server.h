#pragma once
// The edge side of the wire: a gRPC server that hosts many client sessions at once. What a
// session does with its keyframes (global map, mapping, segmentation) is the backend's business;
// the server does transport, validation, ordering, slice retention, idle clean-up and accounting.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "map/map_records.h"
#include "util/timing_stats.h"
#include "wire/server_security.h"
#include "wire/slice_sink.h"
#include "wire/wire_types.h"

namespace edgeslam {

// What a session's back end has spent, for the server's metrics: wall ms per unit of work, by stage
// (per keyframe mapped, per loop detection, per global BA...), and the size of its map.
struct BackendCosts {
  std::uint64_t map_keyframes = 0;
  std::uint64_t map_points = 0;
  std::vector<std::pair<std::string, PercentileSummary>> stages_ms;
};

// One client session on the edge. Calls on one backend never overlap (the server serialises
// them), but they run on the server's RPC threads: return quickly and do heavy work elsewhere.
class EdgeSessionBackend {
 public:
  virtual ~EdgeSessionBackend() = default;
  // A new keyframe, in increasing upload sequence (gaps are uploads the client dropped; retries
  // of an upload already passed on are filtered out). Descriptors the client left out (keypoints
  // of points the edge has) are zero rows flagged in keyframe.features.descriptor_omitted.
  // Throwing std::invalid_argument rejects the client's input (INVALID_ARGUMENT: an image that
  // does not decode, say); anything else is the edge's failure (INTERNAL). The same for onFrame.
  // Images reach the backend checked against the camera from their headers (received_image_check).
  virtual void onKeyFrame(KeyFrameUpload upload) = 0;
  // A whole frame in offload mode. nullopt: this backend does not track frames (the client gets
  // UNIMPLEMENTED).
  virtual std::optional<OffloadResult> onFrame(OffloadFrame /*frame*/) { return std::nullopt; }
  // The client lost its map (or the server lost its session): push a slice with full_resync set
  // as soon as possible.
  virtual void onFullResyncRequested() {}
  // Ids of the session's id origin that its map already holds (a stored map loaded), up to this
  // one; 0 = none. Told to the client when the session opens.
  virtual std::uint64_t idFloor() const { return 0; }
  // Why the session's back end can go on no more (a worker thread ended with an exception);
  // nullopt while it works. Any thread, any time: the server asks before each call and ends a
  // failed session (ABORTED to its client, the cause in its log and metrics).
  virtual std::optional<std::string> failure() const { return std::nullopt; }
  // Unlike the calls above, from any thread while the session runs (the server's metrics).
  virtual BackendCosts costs() const { return {}; }
};

class EdgeSessionFactory {
 public:
  virtual ~EdgeSessionFactory() = default;
  // Opens a backend for a new session; `sink` stays valid for the backend's whole life. Throwing
  // refuses the session (std::invalid_argument -> INVALID_ARGUMENT, others -> INTERNAL, the
  // message passed on).
  virtual std::unique_ptr<EdgeSessionBackend> open(const SessionConfig& config,
                                                   SliceSink& sink) = 0;
};

struct EdgeServerLimits {
  std::size_t max_message_bytes = 8u << 20;        // largest request accepted
  std::size_t max_send_message_bytes = 64u << 20;  // largest slice / reply sent
  std::size_t max_sessions = 64;                   // at most 255 (one id-origin byte each)
  std::chrono::milliseconds idle_timeout{60000};   // no RPC and no open slice stream for so long
  std::chrono::milliseconds stream_poll{200};      // how often a waiting stream checks shutdown
  std::size_t max_kept_slices = 256;               // per session, unacknowledged
  std::size_t max_kept_slice_bytes = 64u << 20;    // per session
  std::size_t max_probe_reply_bytes = 4u << 20;
  // Per client (per token; without tokens every client is one): open sessions at most.
  std::size_t max_sessions_per_client = 8;
  // When every session slot is taken, the session idle longest (no RPC and no slice stream for
  // at least this long) is closed to make room: unused sessions cannot lock others out.
  std::chrono::milliseconds reclaim_idle_after{5000};
  // Per session: keyframe uploads and offloaded frames per second (with a burst of as many).
  double max_uploads_per_second = 200.0;
};

struct SessionStats {
  std::uint64_t session_id = 0;
  std::uint8_t id_origin = 0;
  std::string client_name;
  std::uint64_t uplink_bytes = 0;       // serialized request bytes received in this session
  std::uint64_t downlink_bytes = 0;     // serialized reply and slice bytes sent
  std::uint64_t keyframes = 0;          // uploads passed on to the backend
  std::uint64_t duplicate_uploads = 0;  // retries, or older than an upload already passed on
  std::uint64_t missing_uploads = 0;    // sequence gaps: uploads the client dropped or lost
  std::uint64_t frames = 0;             // offloaded frames
  std::uint64_t slices_pushed = 0;
  std::uint64_t slices_sent = 0;
  std::uint64_t slices_dropped = 0;  // dropped unacknowledged (queue bounds)
  std::uint64_t slices_acknowledged = 0;
  bool streaming = false;
  BackendCosts costs;
};

// What the sessions closed so far had received and left undelivered, summed: a client that
// vanished (killed, link gone) shows up here once the idle reaper closes its session.
struct ClosedSessionTotals {
  std::uint64_t sessions = 0;
  std::uint64_t closed_by_client = 0;
  std::uint64_t closed_idle = 0;       // the client went silent for the idle timeout
  std::uint64_t closed_reclaimed = 0;  // unused, closed to make room for a new session
  std::uint64_t closed_at_shutdown = 0;
  std::uint64_t closed_failed = 0;  // a worker of the session's back end failed (logged cause)
  std::uint64_t keyframes = 0;
  std::uint64_t duplicate_uploads = 0;
  std::uint64_t missing_uploads = 0;
  std::uint64_t slices_pushed = 0;
  std::uint64_t slices_dropped = 0;  // dropped unacknowledged while the session ran
  // Made but never acknowledged by the client; a clean close leaves its last slice here too
  // (applied, but acknowledgements ride on uploads and none followed).
  std::uint64_t slices_unacknowledged = 0;
  // The sessions closed last (at most kRecentClosedSessions), oldest first, as they closed.
  std::vector<SessionStats> recent;
  static constexpr std::size_t kRecentClosedSessions = 16;
};

class EdgeServer {
 public:
  // Listens at e.g. "0.0.0.0:50051" or "127.0.0.1:0" (any free port: see port()). Throws
  // std::runtime_error when the address cannot be bound.
  // `security`: TLS and client tokens (server_security.h); by default plaintext and open.
  EdgeServer(const std::string& listen_address, std::shared_ptr<EdgeSessionFactory> factory,
             EdgeServerLimits limits = {}, EdgeServerSecurity security = {});
  ~EdgeServer();  // shutdown()
  EdgeServer(const EdgeServer&) = delete;
  EdgeServer& operator=(const EdgeServer&) = delete;

  int port() const;
  std::string address() const;  // host:port actually bound

  // Ends every stream and session, then stops; returns within about a second even with clients
  // still connected. Idempotent.
  void shutdown();

  // With `costs`, each session's back end is asked what it spent (SessionStats::costs): summaries
  // of every timing so far, worth it for the metrics file, not for every view.
  std::vector<SessionStats> sessions(bool costs = false) const;
  std::size_t sessionCount() const;
  // Sessions closed because their client went silent.
  std::uint64_t idleSessionsClosed() const;
  ClosedSessionTotals closedSessions() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace edgeslam
