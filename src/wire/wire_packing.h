#pragma once
// Byte layouts of the packed columns of proto/edgeslam/v1 (fixed-width little-endian values in a
// bytes field), their quantisation steps, and the delta coding of id lists. Internal to the wire
// conversions (wire_encode.cpp, wire_decode.cpp).
#include <fmt/format.h>

#include <bit>
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "wire/wire_error.h"

namespace edgeslam::wire_packing {

// Keypoint coordinates travel in 1/32 px: at most 1/64 px off, far below ORB keypoint noise.
constexpr int kCoordinateSteps = 32;
// Larger coordinates than this (in px) are not a keypoint of any camera: refused when encoding.
constexpr double kMaxCoordinate = 1.0e6;
// Angles in 1/256 turn (one byte, at most 0.7 degrees off) or 1/65536 turn (two bytes).
constexpr double angleStepsPerDegree(int bytes) {
  return (bytes == 1 ? 256.0 : 65536.0) / 360.0;
}
// Depths in millimetres (uint16, 0 = unknown): at most 0.5 mm off, up to 65.535 m.
constexpr double kDepthStepsPerMetre = 1000.0;
constexpr std::uint32_t kMaxDepthSteps = 65535;
// Normals as int16 per component: at most 1.6e-5 off per component.
constexpr double kNormalSteps = 32767.0;
constexpr std::size_t kPoseFloats = 7;  // qw qx qy qz tx ty tz

inline void putUnsigned(std::string& out, std::uint64_t value, int bytes) {
  for (int b = 0; b < bytes; ++b) out.push_back(static_cast<char>((value >> (8 * b)) & 0xffu));
}

inline void putFloat(std::string& out, float value) {
  putUnsigned(out, std::bit_cast<std::uint32_t>(value), 4);
}

// Reads `count` values of `width` bytes from a bytes field after checking its length.
class Column {
 public:
  Column(const std::string& bytes, std::size_t count, int width, std::string_view field)
      : bytes_(bytes), width_(width) {
    if (bytes.size() != count * static_cast<std::size_t>(width)) {
      throw WireError(fmt::format("{} holds {} bytes, expected {} x {} = {}", field, bytes.size(),
                                  count, width, count * static_cast<std::size_t>(width)));
    }
  }

  std::uint64_t unsignedAt(std::size_t i) const {
    std::uint64_t value = 0;
    const std::size_t offset = i * static_cast<std::size_t>(width_);
    for (int b = 0; b < width_; ++b) {
      value |= static_cast<std::uint64_t>(static_cast<unsigned char>(bytes_[offset + b]))
               << (8 * b);
    }
    return value;
  }
  std::int16_t int16At(std::size_t i) const {
    return static_cast<std::int16_t>(static_cast<std::uint16_t>(unsignedAt(i)));
  }
  float floatAt(std::size_t i) const {
    return std::bit_cast<float>(static_cast<std::uint32_t>(unsignedAt(i)));
  }

 private:
  const std::string& bytes_;
  int width_;
};

// Id lists travel as differences modulo 2^64 (zig-zag varints on the wire: small either way).
inline std::int64_t idDelta(std::uint64_t id, std::uint64_t previous) {
  return static_cast<std::int64_t>(id - previous);
}
inline std::uint64_t applyIdDelta(std::uint64_t previous, std::int64_t delta) {
  return previous + static_cast<std::uint64_t>(delta);
}

}  // namespace edgeslam::wire_packing
