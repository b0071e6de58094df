// An offloaded frame: decoded, then its colour and depth image headers checked against a
// 640 x 480 camera (what the edge does before it decodes them).
#include "fuzz_camera.h"
#include "fuzz_wire_message.h"
#include "wire/received_image_check.h"
#include "wire/wire_convert.h"

namespace {
void decode(const edgeslam::v1::OffloadFrameRequest& request) {
  const edgeslam::OffloadFrame frame = edgeslam::fromProto(request);
  edgeslam::checkOffloadedImages(frame, edgeslam::fuzz::camera());
}
}  // namespace

EDGESLAM_FUZZ_WIRE_MESSAGE(edgeslam::v1::OffloadFrameRequest, decode)
