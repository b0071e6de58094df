#pragma once
// A 256-bit binary descriptor held as four 64-bit words: the vocabulary's node centres and the
// training set use this form so that a Hamming distance is four popcounts on aligned data.
#include <array>
#include <bit>
#include <cstdint>
#include <cstring>

#include "features/descriptor_distance.h"

namespace edgeslam {

struct Descriptor256 {
  std::array<std::uint64_t, 4> words{};

  // Bit b (0..255) is bit (b % 8) of byte (b / 8) of the OpenCV row, so the byte layout is the
  // same as the 32-byte descriptor on any little-endian CPU.
  static Descriptor256 fromBytes(const std::uint8_t* bytes) {
    Descriptor256 d;
    std::memcpy(d.words.data(), bytes, kDescriptorBytes);
    return d;
  }
  void toBytes(std::uint8_t* bytes) const { std::memcpy(bytes, words.data(), kDescriptorBytes); }

  friend bool operator==(const Descriptor256&, const Descriptor256&) = default;
};

static_assert(std::endian::native == std::endian::little,
              "Descriptor256 assumes the byte order of OpenCV descriptor rows (little-endian)");

inline int hammingDistance(const Descriptor256& a, const Descriptor256& b) {
  return std::popcount(a.words[0] ^ b.words[0]) + std::popcount(a.words[1] ^ b.words[1]) +
         std::popcount(a.words[2] ^ b.words[2]) + std::popcount(a.words[3] ^ b.words[3]);
}

}  // namespace edgeslam
