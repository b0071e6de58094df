#pragma once
// Checks the images a client sends (offloaded frames, keyframe images for segmentation) against
// the session's camera from their headers alone, before anything decodes them: a small message
// declaring a huge image must not make the edge allocate it. Throws WireError (the client gets
// INVALID_ARGUMENT).
#include "geometry/camera.h"
#include "map/map_records.h"
#include "wire/wire_types.h"

namespace edgeslam {

namespace wire_limits {
// A decoded image may take at most this many bytes, whatever camera the session declared
// (a 4096 x 4096 colour image takes 48 MiB).
constexpr std::size_t kMaxDecodedImageBytes = 64u << 20;
// Keyframe images travel at 1/N of the camera's size (the client's --segment-reduce).
constexpr int kMaxKeyFrameImageReduction = 16;
}  // namespace wire_limits

// The colour image at the camera's size, 8 bits; the depth image (when any) at the camera's size,
// one 16-bit channel.
void checkOffloadedImages(const OffloadFrame& frame, const PinholeCamera& camera);

// The keyframe image (when any) at the camera's size divided by N (rounded up), N 1..16, 8 bits.
void checkKeyFrameImage(const KeyFrameUpload& upload, const PinholeCamera& camera);

}  // namespace edgeslam
