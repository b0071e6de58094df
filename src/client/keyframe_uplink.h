#pragma once
// Where the client's keyframe uploads go: the gRPC client, or a direct call in tests. `send` must
// not block tracking for long (queue and return).
#include "map/map_records.h"

namespace edgeslam {

class KeyFrameUplink {
 public:
  virtual ~KeyFrameUplink() = default;
  virtual void send(KeyFrameUpload upload) = 0;
  // The edge is unreachable for now (uploads wait in the uplink's queue until it is back).
  virtual bool reconnecting() const { return false; }
};

}  // namespace edgeslam
