#pragma once
// A slice too big for one message (a full resync of a large map, say) goes out as several: first
// parts that carry only records (keyframes, then points, then point positions, then masks), then
// the original slice's remainder with everything else (sequence fields, poses, erasures, the
// full_resync flag), so that a client acting on that last part has every record already.
#include <cstddef>
#include <functional>
#include <stdexcept>
#include <vector>

#include "map/map_records.h"
#include "wire/slice_sink.h"

namespace edgeslam {

// One record alone is larger than a message may be: the slice cannot be split to fit.
class SliceTooLarge : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Parts of `slice`, in the order to send them, each of `size` at most `max_bytes`. Throws
// SliceTooLarge when a single record does not fit.
std::vector<MapSlice> splitSlice(MapSlice slice, std::size_t max_bytes,
                                 const std::function<std::size_t(const MapSlice&)>& size);

struct SlicePushResult {
  std::size_t parts = 0;  // slices pushed (1 = not split)
  bool sent = false;      // false: not sent at all (logged by the caller)
};

// Pushes `slice`, split when larger than the sink takes. Throws what push() throws for other
// reasons (WireError: not encodable) and SliceTooLarge.
SlicePushResult pushSplitting(SliceSink& sink, MapSlice slice);

}  // namespace edgeslam
