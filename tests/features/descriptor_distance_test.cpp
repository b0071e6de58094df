#include "features/descriptor_distance.h"

#include <gtest/gtest.h>

namespace edgeslam {
namespace {

TEST(DescriptorDistance, EqualsOpenCvHammingNorm) {
  cv::RNG rng(7);
  cv::Mat a(200, 32, CV_8UC1), b(200, 32, CV_8UC1);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  rng.fill(b, cv::RNG::UNIFORM, 0, 256);
  for (int i = 0; i < a.rows; ++i) {
    EXPECT_EQ(descriptorDistance(a, i, b, i), cv::norm(a.row(i), b.row(i), cv::NORM_HAMMING));
  }
}

TEST(DescriptorDistance, ExtremesAndSingleBits) {
  std::uint8_t zeros[32] = {}, ones[32];
  std::fill(std::begin(ones), std::end(ones), 0xFF);
  EXPECT_EQ(descriptorDistance(zeros, zeros), 0);
  EXPECT_EQ(descriptorDistance(zeros, ones), 256);
  for (int bit = 0; bit < 256; ++bit) {
    std::uint8_t one_bit[32] = {};
    one_bit[bit / 8] = static_cast<std::uint8_t>(1u << (bit % 8));
    ASSERT_EQ(descriptorDistance(zeros, one_bit), 1) << "bit " << bit;
  }
}

TEST(DescriptorDistance, UnalignedRowsWork) {
  std::uint8_t buffer[70] = {};
  buffer[1] = 0x0F;   // first descriptor starts at byte 1
  buffer[42] = 0x01;  // second starts at byte 37; this is its byte 5
  EXPECT_EQ(descriptorDistance(buffer + 1, buffer + 37), 5);
}

}  // namespace
}  // namespace edgeslam
