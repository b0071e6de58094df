// An uploaded keyframe: decoded, then its image header checked against a 640 x 480 camera.
#include "fuzz_camera.h"
#include "fuzz_wire_message.h"
#include "wire/received_image_check.h"
#include "wire/wire_convert.h"

namespace {
void decode(const edgeslam::v1::UploadKeyFrameRequest& request) {
  const edgeslam::KeyFrameUpload upload = edgeslam::fromProto(request.upload());
  edgeslam::checkKeyFrameImage(upload, edgeslam::fuzz::camera());
}
}  // namespace

EDGESLAM_FUZZ_WIRE_MESSAGE(edgeslam::v1::UploadKeyFrameRequest, decode)
