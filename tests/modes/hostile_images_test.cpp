// Hostile images against the real edge server and its real SLAM backend: a small message that
// declares a huge image, random bytes, a mislabelled or corrupt image. Each is refused with
// INVALID_ARGUMENT before anything large is allocated, and valid frames still pass.
#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <zlib.h>

#include <opencv2/imgcodecs.hpp>
#include <random>

#include "edgeslam/v1/edgeslam.grpc.pb.h"
#include "modes/slam_session_backend.h"
#include "wire/edge_server.h"
#include "wire/net_test_records.h"
#include "wire/wire_convert.h"

namespace edgeslam {
namespace {

using ::testing::HasSubstr;

void appendBigEndian(std::vector<std::uint8_t>& out, std::uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<std::uint8_t>(v >> shift));
}

void appendChunk(std::vector<std::uint8_t>& png, const char* type,
                 const std::vector<std::uint8_t>& data) {
  appendBigEndian(png, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  const uLong crc = crc32(0L, png.data() + start, static_cast<uInt>(png.size() - start));
  appendBigEndian(png, static_cast<std::uint32_t>(crc));
}

// A complete, valid, black 8-bit grey PNG of width x height, deflated row by row (a 20000 x 20000
// one is about 400 KB: what the hostile-client probe sent).
std::vector<std::uint8_t> blackPng(std::uint32_t width, std::uint32_t height) {
  std::vector<std::uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  std::vector<std::uint8_t> ihdr;
  appendBigEndian(ihdr, width);
  appendBigEndian(ihdr, height);
  ihdr.insert(ihdr.end(), {8, 0, 0, 0, 0});
  appendChunk(png, "IHDR", ihdr);
  z_stream z{};
  EXPECT_EQ(deflateInit(&z, Z_BEST_COMPRESSION), Z_OK);
  std::vector<std::uint8_t> row(width + 1, 0);  // filter byte 0, then black pixels
  std::vector<std::uint8_t> compressed;
  std::vector<std::uint8_t> buffer(1 << 16);
  for (std::uint32_t y = 0; y < height; ++y) {
    z.next_in = row.data();
    z.avail_in = static_cast<uInt>(row.size());
    const int flush = y + 1 == height ? Z_FINISH : Z_NO_FLUSH;
    do {
      z.next_out = buffer.data();
      z.avail_out = static_cast<uInt>(buffer.size());
      deflate(&z, flush);
      compressed.insert(compressed.end(), buffer.data(),
                        buffer.data() + (buffer.size() - z.avail_out));
    } while (z.avail_out == 0 || (flush == Z_FINISH && z.avail_in > 0));
  }
  deflateEnd(&z);
  appendChunk(png, "IDAT", compressed);
  appendChunk(png, "IEND", {});
  return png;
}

long peakRssKb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss;
}

class HostileImages : public ::testing::Test {
 protected:
  void SetUp() override {
    server_ = std::make_unique<EdgeServer>("127.0.0.1:0", std::make_shared<SlamSessionFactory>());
    stub_ = v1::EdgeSlam::NewStub(
        grpc::CreateChannel(server_->address(), grpc::InsecureChannelCredentials()));
    SessionConfig config = test::sampleSessionConfig("hostile");  // 640 x 480
    config.sensor = Sensor::kMonocular;
    v1::OpenSessionRequest open;
    toProto(config, &open);
    open.mutable_header()->set_protocol_version(kWireProtocolVersion);
    v1::OpenSessionReply opened;
    grpc::ClientContext context;
    ASSERT_TRUE(stub_->OpenSession(&context, open, &opened).ok());
    session_id_ = opened.session_id();
  }

  grpc::Status offload(const std::string& encoding, const std::vector<std::uint8_t>& image,
                       v1::OffloadFrameReply* reply = nullptr) {
    v1::OffloadFrameRequest request;
    request.mutable_header()->set_protocol_version(kWireProtocolVersion);
    request.mutable_header()->set_session_id(session_id_);
    request.set_frame_index(++frame_index_);
    request.set_timestamp(static_cast<double>(frame_index_) / 30.0);
    request.set_image_encoding(encoding);
    request.set_image(std::string(image.begin(), image.end()));
    v1::OffloadFrameReply ignored;
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(30));
    return stub_->OffloadFrame(&context, request, reply != nullptr ? reply : &ignored);
  }

  grpc::Status uploadKeyFrame(const std::string& encoding, const std::vector<std::uint8_t>& image) {
    std::mt19937 rng(3);
    KeyFrameUpload upload = test::sampleUpload(++upload_sequence_, 50, 0, rng);
    upload.image_encoding = encoding;
    upload.image_bytes = image;
    v1::UploadKeyFrameRequest request;
    request.mutable_header()->set_protocol_version(kWireProtocolVersion);
    request.mutable_header()->set_session_id(session_id_);
    toProto(upload, request.mutable_upload());
    v1::UploadKeyFrameReply reply;
    grpc::ClientContext context;
    return stub_->UploadKeyFrame(&context, request, &reply);
  }

  std::unique_ptr<EdgeServer> server_;
  std::unique_ptr<v1::EdgeSlam::Stub> stub_;
  std::uint64_t session_id_ = 0;
  std::uint64_t frame_index_ = 0;
  std::uint64_t upload_sequence_ = 0;
};

TEST_F(HostileImages, AHugeDeclaredPngIsRefusedBeforeItIsDecoded) {
  const std::vector<std::uint8_t> huge = blackPng(20000, 20000);
  ASSERT_LT(huge.size(), 1000000U);  // a small message...
  EXPECT_EQ(cv::imdecode(blackPng(64, 48), cv::IMREAD_UNCHANGED).size(), cv::Size(64, 48));
  const long rss_before_kb = peakRssKb();
  const grpc::Status status = offload("png", huge);  // ...declaring 400 MB of pixels
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("20000 x 20000"));
  EXPECT_LT(peakRssKb() - rss_before_kb, 100 * 1024) << "the server decoded the image";

  const grpc::Status upload_status = uploadKeyFrame("png", huge);
  EXPECT_EQ(upload_status.error_code(), grpc::StatusCode::INVALID_ARGUMENT)
      << upload_status.error_message();
  EXPECT_THAT(upload_status.error_message(), HasSubstr("20000 x 20000"));
  EXPECT_LT(peakRssKb() - rss_before_kb, 100 * 1024) << "the server decoded the image";
}

TEST_F(HostileImages, ClientInputErrorsAreInvalidArgument) {
  std::mt19937 rng(11);
  std::vector<std::uint8_t> random_bytes(5000);
  for (auto& b : random_bytes) b = static_cast<std::uint8_t>(rng());
  grpc::Status status = offload("jpeg", random_bytes);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("not a readable PNG or JPEG"));

  // The right header, then garbage: only a decode finds out.
  std::vector<std::uint8_t> corrupt = blackPng(640, 480);
  corrupt.resize(60);
  corrupt.insert(corrupt.end(), random_bytes.begin(), random_bytes.end());
  status = offload("png", corrupt);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("undecodable"));

  status = offload("jpeg", blackPng(640, 480));
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("declared jpeg but is a png"));

  std::vector<std::uint8_t> small;
  cv::imencode(".jpg", cv::Mat(240, 320, CV_8UC1, cv::Scalar(128)), small);
  status = offload("jpeg", small);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();
  EXPECT_THAT(status.error_message(), HasSubstr("320 x 240 but the session's camera is 640 x 480"));

  status = uploadKeyFrame("jpeg", random_bytes);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT) << status.error_message();

  // A frame of the camera's size still goes through to the SLAM.
  cv::Mat frame(480, 640, CV_8UC1);
  cv::randu(frame, 0, 255);
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", frame, jpeg);
  v1::OffloadFrameReply reply;
  status = offload("jpeg", jpeg, &reply);
  EXPECT_TRUE(status.ok()) << status.error_message();
  EXPECT_EQ(reply.frame_index(), frame_index_);
}

}  // namespace
}  // namespace edgeslam
