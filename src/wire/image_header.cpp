#include "wire/image_header.h"

#include <array>
#include <cstring>

namespace edgeslam {
namespace {

constexpr std::array<std::uint8_t, 8> kPngSignature{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

std::uint32_t bigEndian32(const std::uint8_t* p) {
  return (std::uint32_t{p[0]} << 24) | (std::uint32_t{p[1]} << 16) | (std::uint32_t{p[2]} << 8) |
         std::uint32_t{p[3]};
}

std::uint16_t bigEndian16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

std::optional<ImageHeader> fail(std::string* error, const char* message) {
  if (error != nullptr) *error = message;
  return std::nullopt;
}

// PNG: the signature, then the IHDR chunk first (length 13): width, height, bit depth, colour type.
std::optional<ImageHeader> readPng(std::span<const std::uint8_t> b, std::string* error) {
  constexpr std::size_t kIhdrEnd = 8 + 8 + 13;
  if (b.size() < kIhdrEnd) return fail(error, "PNG shorter than its header");
  if (bigEndian32(&b[8]) != 13 || std::memcmp(&b[12], "IHDR", 4) != 0) {
    return fail(error, "PNG does not start with an IHDR chunk");
  }
  const std::uint32_t width = bigEndian32(&b[16]);
  const std::uint32_t height = bigEndian32(&b[20]);
  const int depth = b[24];
  const int colour_type = b[25];
  // The PNG limit is 2^31 - 1; anything above cannot be a valid image.
  if (width == 0 || height == 0 || width > 0x7fffffffu || height > 0x7fffffffu) {
    return fail(error, "PNG declares a zero or invalid size");
  }
  ImageHeader header;
  header.format = ImageHeader::Format::kPng;
  header.width = static_cast<int>(width);
  header.height = static_cast<int>(height);
  switch (colour_type) {
    case 0:  // grey: 1, 2, 4, 8, 16 bits
      if (depth != 1 && depth != 2 && depth != 4 && depth != 8 && depth != 16) break;
      header.channels = 1;
      break;
    case 2:  // RGB: 8, 16
      if (depth != 8 && depth != 16) break;
      header.channels = 3;
      break;
    case 3:  // palette, decoded to colour: 1, 2, 4, 8
      if (depth != 1 && depth != 2 && depth != 4 && depth != 8) break;
      header.channels = 3;
      break;
    case 4:  // grey + alpha: 8, 16
      if (depth != 8 && depth != 16) break;
      header.channels = 2;
      break;
    case 6:  // RGBA: 8, 16
      if (depth != 8 && depth != 16) break;
      header.channels = 4;
      break;
    default:
      break;
  }
  if (header.channels == 0) return fail(error, "PNG declares an invalid colour type or bit depth");
  header.bits_per_channel = depth == 16 ? 16 : 8;
  return header;
}

bool isStartOfFrame(std::uint8_t marker) {
  // SOF0..SOF15 except DHT (C4), JPG (C8) and DAC (CC).
  return marker >= 0xc0 && marker <= 0xcf && marker != 0xc4 && marker != 0xc8 && marker != 0xcc;
}

// JPEG: markers from SOI on; the first start-of-frame segment holds precision, height, width and
// the number of components. Segments before it (APPn, DQT, DHT, ...) are skipped by their length.
std::optional<ImageHeader> readJpeg(std::span<const std::uint8_t> b, std::string* error) {
  std::size_t i = 2;  // after SOI
  while (true) {
    if (i >= b.size()) return fail(error, "JPEG ends before its frame header");
    if (b[i] != 0xff) return fail(error, "JPEG marker expected");
    while (i < b.size() && b[i] == 0xff) ++i;  // fill bytes
    if (i >= b.size()) return fail(error, "JPEG ends before its frame header");
    const std::uint8_t marker = b[i++];
    if (marker == 0xd9 || marker == 0xda) return fail(error, "JPEG has no frame header");
    if (marker == 0x01 || (marker >= 0xd0 && marker <= 0xd8)) continue;  // no length
    if (i + 2 > b.size()) return fail(error, "JPEG segment length cut short");
    const std::size_t length = bigEndian16(&b[i]);
    if (length < 2) return fail(error, "JPEG segment length below 2");
    if (isStartOfFrame(marker)) {
      if (length < 8 || i + 8 > b.size()) return fail(error, "JPEG frame header cut short");
      ImageHeader header;
      header.format = ImageHeader::Format::kJpeg;
      const int precision = b[i + 2];
      header.height = bigEndian16(&b[i + 3]);
      header.width = bigEndian16(&b[i + 5]);
      header.channels = b[i + 7];
      // Height 0 defers it to a later DNL marker: not accepted (nothing we send uses it).
      if (header.width == 0 || header.height == 0) {
        return fail(error, "JPEG declares a zero size");
      }
      if (header.channels != 1 && header.channels != 3 && header.channels != 4) {
        return fail(error, "JPEG declares neither 1, 3 nor 4 components");
      }
      if (precision != 8 && precision != 12 && precision != 16) {
        return fail(error, "JPEG declares a precision other than 8, 12 or 16 bits");
      }
      header.bits_per_channel = precision == 8 ? 8 : 16;
      return header;
    }
    i += length;
  }
}

}  // namespace

std::size_t ImageHeader::decodedBytes() const {
  return static_cast<std::size_t>(width) * static_cast<std::size_t>(height) *
         static_cast<std::size_t>(channels) * static_cast<std::size_t>(bits_per_channel / 8);
}

std::optional<ImageHeader> readImageHeader(std::span<const std::uint8_t> bytes,
                                           std::string* error) {
  if (bytes.size() >= kPngSignature.size() &&
      std::memcmp(bytes.data(), kPngSignature.data(), kPngSignature.size()) == 0) {
    return readPng(bytes, error);
  }
  if (bytes.size() >= 2 && bytes[0] == 0xff && bytes[1] == 0xd8) return readJpeg(bytes, error);
  return fail(error, "neither a PNG nor a JPEG");
}

std::string toString(ImageHeader::Format format) {
  return format == ImageHeader::Format::kPng ? "png" : "jpeg";
}

}  // namespace edgeslam
