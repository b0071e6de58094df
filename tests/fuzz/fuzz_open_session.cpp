// A session request (camera, sensor, settings): the control message that sizes everything else.
#include "fuzz_wire_message.h"
#include "wire/wire_convert.h"

namespace {
void decode(const edgeslam::v1::OpenSessionRequest& request) {
  (void)edgeslam::fromProto(request);
}
}  // namespace

EDGESLAM_FUZZ_WIRE_MESSAGE(edgeslam::v1::OpenSessionRequest, decode)
