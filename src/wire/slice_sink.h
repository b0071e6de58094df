#pragma once
// Where an edge session puts the map slices for its client.
#include <cstddef>
#include <cstdint>

#include "map/map_records.h"

namespace edgeslam {

class SliceSink {
 public:
  virtual ~SliceSink() = default;
  // Queues a slice for the client and returns the sequence it was given (1, 2, ...; whatever
  // slice.sequence held is replaced). Thread-safe and never waits on the network. Throws WireError
  // when the slice cannot be encoded or is larger than the server may send in one message.
  virtual std::uint64_t push(MapSlice slice) = 0;
  // The largest encoded slice push() takes (split bigger ones: slice_splitting.h).
  virtual std::size_t maxSliceBytes() const { return SIZE_MAX; }
  // The last slice the client said it applied (0 = none yet).
  virtual std::uint64_t acknowledged() const = 0;
};

}  // namespace edgeslam
