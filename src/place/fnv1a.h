#pragma once
// FNV-1a 64-bit hash: the vocabulary file's checksum.
#include <cstdint>
#include <span>

namespace edgeslam {

inline std::uint64_t fnv1a64(std::span<const std::uint8_t> bytes) {
  std::uint64_t hash = 0xcbf29ce484222325ULL;
  for (const std::uint8_t byte : bytes) {
    hash ^= byte;
    hash *= 0x100000001b3ULL;
  }
  return hash;
}

}  // namespace edgeslam
