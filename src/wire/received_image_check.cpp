#include "wire/received_image_check.h"

#include <fmt/format.h>

#include <string>

#include "wire/image_header.h"
#include "wire/wire_error.h"

namespace edgeslam {
namespace {

ImageHeader readHeader(const std::vector<std::uint8_t>& bytes, const std::string& encoding,
                       const char* what) {
  std::string error;
  const std::optional<ImageHeader> header = readImageHeader(bytes, &error);
  if (!header) {
    throw WireError(fmt::format("{} image ({} bytes) is not a readable PNG or JPEG: {}", what,
                                bytes.size(), error));
  }
  if (toString(header->format) != encoding) {
    throw WireError(fmt::format("{} image is declared {} but is a {}", what, encoding,
                                toString(header->format)));
  }
  if (header->decodedBytes() > wire_limits::kMaxDecodedImageBytes) {
    throw WireError(fmt::format("{} image of {} x {} x {} would decode to {} bytes (limit {})",
                                what, header->width, header->height, header->channels,
                                header->decodedBytes(), wire_limits::kMaxDecodedImageBytes));
  }
  return *header;
}

void requireSize(const ImageHeader& header, int width, int height, const char* what,
                 const PinholeCamera& camera) {
  if (header.width == width && header.height == height) return;
  throw WireError(fmt::format("{} image is {} x {} but the session's camera is {} x {}", what,
                              header.width, header.height, camera.width(), camera.height()));
}

void requireEightBits(const ImageHeader& header, const char* what) {
  if (header.bits_per_channel != 8) {
    throw WireError(fmt::format("{} image has {} bits per channel (expected 8)", what,
                                header.bits_per_channel));
  }
}

}  // namespace

void checkOffloadedImages(const OffloadFrame& frame, const PinholeCamera& camera) {
  const ImageHeader colour = readHeader(frame.image_bytes, frame.image_encoding, "offloaded");
  requireSize(colour, camera.width(), camera.height(), "offloaded", camera);
  requireEightBits(colour, "offloaded");
  if (frame.depth_bytes.empty()) return;
  const ImageHeader depth = readHeader(frame.depth_bytes, frame.depth_encoding, "depth");
  requireSize(depth, camera.width(), camera.height(), "depth", camera);
  if (depth.channels != 1 || depth.bits_per_channel != 16) {
    throw WireError(fmt::format("depth image has {} channel(s) of {} bits (expected one of 16)",
                                depth.channels, depth.bits_per_channel));
  }
}

void checkKeyFrameImage(const KeyFrameUpload& upload, const PinholeCamera& camera) {
  if (upload.image_bytes.empty()) return;
  const ImageHeader header = readHeader(upload.image_bytes, upload.image_encoding, "keyframe");
  requireEightBits(header, "keyframe");
  for (int n = 1; n <= wire_limits::kMaxKeyFrameImageReduction; ++n) {
    if (header.width == (camera.width() + n - 1) / n &&
        header.height == (camera.height() + n - 1) / n) {
      return;
    }
  }
  throw WireError(fmt::format(
      "keyframe image is {} x {}, which is not the session's camera ({} x {}) reduced 1..{} times",
      header.width, header.height, camera.width(), camera.height(),
      wire_limits::kMaxKeyFrameImageReduction));
}

}  // namespace edgeslam
