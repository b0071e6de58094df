#pragma once
// Per-bit counts over a set of 256-bit descriptors, giving their per-bit majority: the "median"
// centre of a Hamming k-medians cluster.
#include <array>
#include <cstdint>

#include "place/binary_descriptor.h"

namespace edgeslam {

class BitMajority {
 public:
  void add(const Descriptor256& d) {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(d.words.data());
    for (int i = 0; i < kDescriptorBytes; ++i) packed_[i] += kSpread[bytes[i]];
    ++count_;
    if (++pending_ == kMaxPending) flush();
  }

  // Adds the counts of `other` (which is flushed first).
  void merge(BitMajority& other) {
    other.flush();
    flush();
    for (int b = 0; b < kDescriptorBits; ++b) bit_counts_[b] += other.bit_counts_[b];
    count_ += other.count_;
  }

  std::uint32_t count() const { return count_; }

  // Bit set where more than half of the added descriptors have it (ties give 0).
  Descriptor256 majority() {
    flush();
    Descriptor256 centre;
    for (int b = 0; b < kDescriptorBits; ++b) {
      if (2 * bit_counts_[b] > count_) centre.words[b / 64] |= std::uint64_t{1} << (b % 64);
    }
    return centre;
  }

 private:
  // Eight 8-bit lanes per byte of the descriptor: adding kSpread[byte] counts all eight bits of
  // that byte at once; lanes are emptied into bit_counts_ before they can overflow.
  static constexpr std::uint32_t kMaxPending = 255;
  static constexpr std::array<std::uint64_t, 256> kSpread = [] {
    std::array<std::uint64_t, 256> table{};
    for (unsigned value = 0; value < 256; ++value) {
      for (unsigned bit = 0; bit < 8; ++bit) {
        if ((value >> bit) & 1U) table[value] |= std::uint64_t{1} << (8 * bit);
      }
    }
    return table;
  }();

  void flush() {
    if (pending_ == 0) return;
    for (int i = 0; i < kDescriptorBytes; ++i) {
      for (int bit = 0; bit < 8; ++bit) {
        bit_counts_[8 * i + bit] += static_cast<std::uint32_t>((packed_[i] >> (8 * bit)) & 0xFFU);
      }
      packed_[i] = 0;
    }
    pending_ = 0;
  }

  std::array<std::uint64_t, kDescriptorBytes> packed_{};
  std::array<std::uint32_t, kDescriptorBits> bit_counts_{};
  std::uint32_t pending_ = 0;
  std::uint32_t count_ = 0;
};

}  // namespace edgeslam
