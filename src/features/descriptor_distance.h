#pragma once
// Hamming distance between 256-bit binary descriptors (ORB: 32 bytes per row of a CV_8UC1 matrix).
#include <bit>
#include <cstdint>
#include <cstring>
#include <opencv2/core.hpp>

namespace edgeslam {

inline constexpr int kDescriptorBytes = 32;
inline constexpr int kDescriptorBits = 8 * kDescriptorBytes;

// Four 64-bit popcounts; memcpy keeps it free of alignment and aliasing assumptions (compilers
// turn it into plain loads).
inline int descriptorDistance(const std::uint8_t* a, const std::uint8_t* b) {
  int distance = 0;
  for (int word = 0; word < kDescriptorBytes / 8; ++word) {
    std::uint64_t wa, wb;
    std::memcpy(&wa, a + 8 * word, 8);
    std::memcpy(&wb, b + 8 * word, 8);
    distance += std::popcount(wa ^ wb);
  }
  return distance;
}

// Distance between row `row_a` of `a` and row `row_b` of `b` (both CV_8UC1 with 32 columns).
inline int descriptorDistance(const cv::Mat& a, int row_a, const cv::Mat& b, int row_b) {
  return descriptorDistance(a.ptr<std::uint8_t>(row_a), b.ptr<std::uint8_t>(row_b));
}

}  // namespace edgeslam
