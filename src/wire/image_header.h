#pragma once
// The size and pixel layout a PNG or JPEG declares in its header, read without decoding the image:
// a received image is checked against the session's camera before anything is allocated for it.
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace edgeslam {

struct ImageHeader {
  enum class Format { kPng, kJpeg };
  Format format = Format::kPng;
  int width = 0;
  int height = 0;
  int channels = 0;          // as stored: 1 grey, 2 grey+alpha, 3 colour (palette too), 4 RGBA
  int bits_per_channel = 0;  // 8 or 16 (PNG 1, 2 and 4 bit images are widened to 8 on decode)

  // Bytes a full decode of the image as stored takes.
  std::size_t decodedBytes() const;
};

// nullopt with `*error` set when `bytes` are not a PNG or JPEG whose header declares a non-zero
// size. Reads at most the bytes given; never throws.
std::optional<ImageHeader> readImageHeader(std::span<const std::uint8_t> bytes, std::string* error);

std::string toString(ImageHeader::Format format);

}  // namespace edgeslam
