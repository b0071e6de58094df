// The image header reader on real encoder output, on crafted headers and on broken bytes; the
// received-image checks against a session's camera.
#include "wire/image_header.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <opencv2/imgcodecs.hpp>
#include <random>

#include "net_test_records.h"
#include "wire/received_image_check.h"
#include "wire/wire_error.h"

namespace edgeslam {
namespace {

using ::testing::HasSubstr;

std::vector<std::uint8_t> encode(const std::string& extension, const cv::Mat& image) {
  std::vector<std::uint8_t> bytes;
  EXPECT_TRUE(cv::imencode(extension, image, bytes));
  return bytes;
}

cv::Mat noise(int rows, int cols, int type) {
  cv::Mat image(rows, cols, type);
  cv::randu(image, 0, 255);
  return image;
}

// A PNG signature and IHDR chunk declaring `width` x `height`, and nothing else.
std::vector<std::uint8_t> pngHeader(std::uint32_t width, std::uint32_t height, int depth = 8,
                                    int colour_type = 0) {
  std::vector<std::uint8_t> b{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n',
                              0,    0,   0,   13,  'I',  'H',  'D',  'R'};
  for (std::uint32_t v : {width, height}) {
    for (int shift = 24; shift >= 0; shift -= 8) b.push_back(static_cast<std::uint8_t>(v >> shift));
  }
  b.insert(b.end(), {static_cast<std::uint8_t>(depth), static_cast<std::uint8_t>(colour_type), 0, 0,
                     0, 0, 0, 0, 0});  // compression, filter, interlace, CRC
  return b;
}

ImageHeader read(const std::vector<std::uint8_t>& bytes) {
  std::string error;
  const auto header = readImageHeader(bytes, &error);
  EXPECT_TRUE(header.has_value()) << error;
  return header.value_or(ImageHeader{});
}

TEST(ImageHeader, ReadsWhatOpenCvEncodes) {
  const ImageHeader grey_png = read(encode(".png", noise(48, 64, CV_8UC1)));
  EXPECT_EQ(grey_png.format, ImageHeader::Format::kPng);
  EXPECT_EQ(grey_png.width, 64);
  EXPECT_EQ(grey_png.height, 48);
  EXPECT_EQ(grey_png.channels, 1);
  EXPECT_EQ(grey_png.bits_per_channel, 8);

  const ImageHeader depth_png = read(encode(".png", noise(30, 50, CV_16UC1)));
  EXPECT_EQ(depth_png.channels, 1);
  EXPECT_EQ(depth_png.bits_per_channel, 16);
  EXPECT_EQ(depth_png.decodedBytes(), 30U * 50U * 2U);

  const ImageHeader colour_png = read(encode(".png", noise(7, 9, CV_8UC3)));
  EXPECT_EQ(colour_png.channels, 3);

  const ImageHeader colour_jpeg = read(encode(".jpg", noise(480, 640, CV_8UC3)));
  EXPECT_EQ(colour_jpeg.format, ImageHeader::Format::kJpeg);
  EXPECT_EQ(colour_jpeg.width, 640);
  EXPECT_EQ(colour_jpeg.height, 480);
  EXPECT_EQ(colour_jpeg.channels, 3);
  EXPECT_EQ(colour_jpeg.bits_per_channel, 8);

  const ImageHeader grey_jpeg = read(encode(".jpg", noise(33, 17, CV_8UC1)));
  EXPECT_EQ(grey_jpeg.width, 17);
  EXPECT_EQ(grey_jpeg.height, 33);
  EXPECT_EQ(grey_jpeg.channels, 1);
}

TEST(ImageHeader, ReadsAHugeDeclaredSizeWithoutDecoding) {
  const ImageHeader header = read(pngHeader(20000, 20000));
  EXPECT_EQ(header.width, 20000);
  EXPECT_EQ(header.height, 20000);
  EXPECT_EQ(header.decodedBytes(), 400000000U);
  EXPECT_EQ(read(pngHeader(0x7fffffffu, 0x7fffffffu, 16, 6)).decodedBytes(),
            std::size_t{0x7fffffffu} * 0x7fffffffu * 8U);
}

TEST(ImageHeader, RefusesBrokenBytes) {
  std::string error;
  EXPECT_FALSE(readImageHeader({}, &error));
  EXPECT_THAT(error, HasSubstr("neither a PNG nor a JPEG"));
  EXPECT_FALSE(readImageHeader(pngHeader(0, 10), &error));
  EXPECT_FALSE(readImageHeader(pngHeader(10, 10, 3, 0), &error));  // 3-bit grey
  EXPECT_THAT(error, HasSubstr("colour type or bit depth"));
  EXPECT_FALSE(readImageHeader(pngHeader(10, 10, 8, 5), &error));
  EXPECT_FALSE(readImageHeader(pngHeader(0x80000000u, 1), &error));

  // Every prefix of real images: refused, never read beyond the end (ASan checks that).
  for (const auto& bytes : {encode(".jpg", noise(20, 30, CV_8UC3)), pngHeader(5, 7)}) {
    const ImageHeader whole = read(bytes);
    for (std::size_t n = 0; n + 1 < std::min<std::size_t>(bytes.size(), 700); ++n) {
      const std::vector<std::uint8_t> prefix(bytes.begin(), bytes.begin() + static_cast<long>(n));
      const auto header = readImageHeader(prefix, &error);
      if (header) {  // a prefix holding the whole header reads as the whole image
        EXPECT_EQ(header->width, whole.width);
        EXPECT_EQ(header->height, whole.height);
      }
    }
  }
  // Random bytes after a JPEG start marker.
  std::mt19937 rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(rng() % 64));
    for (auto& b : bytes) b = static_cast<std::uint8_t>(rng());
    if (trial % 2 == 0) bytes.insert(bytes.begin(), {0xff, 0xd8});
    (void)readImageHeader(bytes, &error);
  }
}

OffloadFrame offloadedFrame(const cv::Mat& image, const std::string& extension = ".jpg") {
  OffloadFrame frame;
  frame.image_encoding = extension == ".jpg" ? "jpeg" : "png";
  frame.image_bytes = encode(extension, image);
  return frame;
}

std::string checkError(const std::function<void()>& check) {
  try {
    check();
  } catch (const WireError& e) {
    return e.what();
  }
  return "accepted";
}

TEST(ReceivedImageCheck, OffloadedFramesMustMatchTheCamera) {
  const PinholeCamera camera = test::sampleSessionConfig().camera;  // 640 x 480
  OffloadFrame frame = offloadedFrame(noise(480, 640, CV_8UC1));
  EXPECT_NO_THROW(checkOffloadedImages(frame, camera));
  frame.depth_encoding = "png";
  frame.depth_bytes = encode(".png", noise(480, 640, CV_16UC1));
  EXPECT_NO_THROW(checkOffloadedImages(frame, camera));

  EXPECT_THAT(
      checkError([&] { checkOffloadedImages(offloadedFrame(noise(240, 320, CV_8UC3)), camera); }),
      HasSubstr("offloaded image is 320 x 240 but the session's camera is 640 x 480"));
  OffloadFrame huge;
  huge.image_encoding = "png";
  huge.image_bytes = pngHeader(20000, 20000);
  EXPECT_THAT(checkError([&] { checkOffloadedImages(huge, camera); }),
              HasSubstr("would decode to 400000000 bytes"));
  huge.image_bytes = pngHeader(4000, 3000);
  EXPECT_THAT(checkError([&] { checkOffloadedImages(huge, camera); }),
              HasSubstr("is 4000 x 3000 but the session's camera is 640 x 480"));
  OffloadFrame mislabelled = offloadedFrame(noise(480, 640, CV_8UC1), ".png");
  mislabelled.image_encoding = "jpeg";
  EXPECT_THAT(checkError([&] { checkOffloadedImages(mislabelled, camera); }),
              HasSubstr("declared jpeg but is a png"));
  OffloadFrame random_bytes;
  random_bytes.image_encoding = "jpeg";
  random_bytes.image_bytes = {1, 2, 3, 4, 5};
  EXPECT_THAT(checkError([&] { checkOffloadedImages(random_bytes, camera); }),
              HasSubstr("not a readable PNG or JPEG"));

  OffloadFrame shallow_depth = frame;
  shallow_depth.depth_bytes = encode(".png", noise(480, 640, CV_8UC1));
  EXPECT_THAT(checkError([&] { checkOffloadedImages(shallow_depth, camera); }),
              HasSubstr("depth image has 1 channel(s) of 8 bits"));
  OffloadFrame small_depth = frame;
  small_depth.depth_bytes = encode(".png", noise(100, 100, CV_16UC1));
  EXPECT_THAT(checkError([&] { checkOffloadedImages(small_depth, camera); }),
              HasSubstr("depth image is 100 x 100"));
}

TEST(ReceivedImageCheck, KeyFrameImagesMayBeReduced) {
  const PinholeCamera camera = test::sampleSessionConfig().camera;  // 640 x 480
  KeyFrameUpload upload;
  EXPECT_NO_THROW(checkKeyFrameImage(upload, camera));  // no image
  upload.image_encoding = "jpeg";
  for (const cv::Size size : {cv::Size(640, 480), cv::Size(320, 240), cv::Size(214, 160)}) {
    upload.image_bytes = encode(".jpg", noise(size.height, size.width, CV_8UC3));
    EXPECT_NO_THROW(checkKeyFrameImage(upload, camera)) << size;
  }
  upload.image_bytes = encode(".jpg", noise(240, 321, CV_8UC3));
  EXPECT_THAT(checkError([&] { checkKeyFrameImage(upload, camera); }),
              HasSubstr("keyframe image is 321 x 240, which is not the session's camera"));
  upload.image_encoding = "png";
  upload.image_bytes = pngHeader(20000, 20000);
  EXPECT_THAT(checkError([&] { checkKeyFrameImage(upload, camera); }),
              HasSubstr("would decode to"));
  upload.image_bytes = encode(".png", noise(480, 640, CV_16UC1));
  EXPECT_THAT(checkError([&] { checkKeyFrameImage(upload, camera); }),
              HasSubstr("16 bits per channel"));
}

}  // namespace
}  // namespace edgeslam
