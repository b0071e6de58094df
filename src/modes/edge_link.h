#pragma once
// The client's connection to its edge session: keyframe uploads out, map slices in. Implemented
// over gRPC (the real split) and in-process (tests, no network).
#include <cstdint>
#include <functional>
#include <vector>

#include "client/keyframe_uplink.h"
#include "map/ids.h"
#include "map/map_records.h"

namespace edgeslam {

class EdgeClient;

struct EdgeLinkCounters {
  std::uint64_t uplink_bytes = 0;
  std::uint64_t downlink_bytes = 0;
  std::uint64_t uploads_dropped = 0;
  std::uint64_t uploads_overflowed = 0;  // of those, pushed out of a full upload queue
  std::uint64_t reconnects = 0;
};

class EdgeLink : public KeyFrameUplink {
 public:
  using SliceHandler = std::function<void(MapSlice)>;
  // An upload the link gave up on for good while the session runs (its sequence, the keyframe it
  // carried): the edge will never see it. Called on the link's thread or on the sender's (an
  // upload pushed out of a full queue), never under the link's own locks.
  using UploadDroppedHandler = std::function<void(std::uint64_t sequence, KeyFrameId keyframe)>;

  // The id origin byte the session gave this client (its map element ids start with it).
  virtual std::uint8_t idOrigin() const = 0;
  // Ids of that origin the edge's map already held when the session opened (a stored map the
  // edge resumed): the client makes its ids above. 0 = none.
  virtual std::uint64_t idFloor() const { return 0; }
  // Keyframes whose upload the link still holds (queued or being sent), or that the edge's session
  // took while a full resync was pending (after the resync's snapshot, perhaps): after a full
  // resync they are on their way, not lost.
  virtual std::vector<KeyFrameId> pendingKeyFrames() const { return {}; }
  // Called on the link's own thread for every slice; set before the first upload.
  virtual void setSliceHandler(SliceHandler handler) = 0;
  // Set before the first upload. The default suits a link that never drops an upload.
  virtual void setUploadDroppedHandler(UploadDroppedHandler /*handler*/) {}
  virtual EdgeLinkCounters counters() const = 0;
  virtual void close() = 0;
  // The gRPC client under this link, for probing; nullptr when there is no network.
  virtual EdgeClient* edgeClient() { return nullptr; }
};

}  // namespace edgeslam
