// A map slice, as the client decodes it from the edge's stream.
#include "fuzz_wire_message.h"
#include "wire/wire_convert.h"

namespace {
void decode(const edgeslam::v1::MapSlice& slice) {
  (void)edgeslam::fromProto(slice);
}
}  // namespace

EDGESLAM_FUZZ_WIRE_MESSAGE(edgeslam::v1::MapSlice, decode)
