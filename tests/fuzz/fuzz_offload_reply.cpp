// The edge's answer to an offloaded frame, as the client decodes it.
#include "fuzz_wire_message.h"
#include "wire/wire_convert.h"

namespace {
void decode(const edgeslam::v1::OffloadFrameReply& reply) {
  (void)edgeslam::fromProto(reply);
}
}  // namespace

EDGESLAM_FUZZ_WIRE_MESSAGE(edgeslam::v1::OffloadFrameReply, decode)
