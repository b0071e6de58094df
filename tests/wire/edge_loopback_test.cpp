// Client and server in one process over loopback: the normal path, and what the server does with
// requests it must refuse.
#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <random>

#include "edgeslam/v1/edgeslam.grpc.pb.h"
#include "fake_edge_backend.h"
#include "net_test_records.h"
#include "wire/edge_client.h"
#include "wire/edge_server.h"
#include "wire/wire_convert.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;
using test::FakeFactory;
using test::SliceCollector;
using ::testing::HasSubstr;

std::unique_ptr<v1::EdgeSlam::Stub> rawStub(const std::string& address) {
  return v1::EdgeSlam::NewStub(grpc::CreateChannel(address, grpc::InsecureChannelCredentials()));
}

v1::RequestHeader headerFor(std::uint64_t session, std::uint32_t version = kWireProtocolVersion) {
  v1::RequestHeader header;
  header.set_protocol_version(version);
  header.set_session_id(session);
  return header;
}

std::uint64_t openRawSession(v1::EdgeSlam::Stub& stub) {
  v1::OpenSessionRequest request;
  toProto(test::sampleSessionConfig("raw"), &request);
  *request.mutable_header() = headerFor(0);
  v1::OpenSessionReply reply;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + 10s);
  const grpc::Status status = stub.OpenSession(&context, request, &reply);
  EXPECT_TRUE(status.ok()) << status.error_message();
  return reply.session_id();
}

grpc::Status rawUpload(v1::EdgeSlam::Stub& stub, const v1::UploadKeyFrameRequest& request) {
  v1::UploadKeyFrameReply reply;
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + 10s);
  return stub.UploadKeyFrame(&context, request, &reply);
}

class EdgeLoopback : public ::testing::Test {
 protected:
  void SetUp() override { startServer(4); }

  void startServer(std::size_t kept_slices) {
    server.reset();
    factory = std::make_shared<FakeFactory>();
    EdgeServerLimits limits;
    limits.max_message_bytes = 1u << 20;
    limits.max_kept_slices = kept_slices;
    server = std::make_unique<EdgeServer>("127.0.0.1:0", factory, limits);
  }

  EdgeClientOptions clientOptions(SliceCollector* collector = nullptr) {
    EdgeClientOptions options;
    options.connect_timeout = 10s;
    if (collector != nullptr) options.on_slice = collector->callback();
    return options;
  }

  std::shared_ptr<FakeFactory> factory;
  std::unique_ptr<EdgeServer> server;
};

TEST_F(EdgeLoopback, UploadsReachTheBackendInOrderAndSlicesStreamBack) {
  // Slices are acknowledged only by later uploads: with fewer kept than the uploads below, a busy
  // host's slow stream writer would see the first ones dropped and ask for a resync instead.
  startServer(16);
  SliceCollector collector;
  EdgeClient client(server->address(), test::sampleSessionConfig(), clientOptions(&collector));
  ASSERT_GE(client.idOrigin(), 1);
  auto log = factory->session(0);
  ASSERT_NE(log, nullptr);
  EXPECT_EQ(log->config.client_name, "test-client");
  EXPECT_EQ(log->config.sensor, Sensor::kRgbd);
  EXPECT_EQ(log->config.camera.fx(), 585.0);
  EXPECT_EQ(log->config.id_origin, client.idOrigin());

  std::mt19937 rng(21);
  constexpr int kUploads = 6;  // within the queue's capacity: none may be dropped
  for (int i = 0; i < kUploads; ++i) {
    EXPECT_EQ(client.uploadKeyFrame(test::sampleUpload(0, 300, 20, rng)),
              static_cast<std::uint64_t>(i + 1));
  }
  ASSERT_TRUE(client.flushUploads(10s));
  ASSERT_TRUE(log->waitFor([](auto& l) { return l.upload_sequences.size() == kUploads; }));
  {
    std::lock_guard lock(log->mutex);
    EXPECT_EQ(log->upload_sequences, (std::vector<std::uint64_t>{1, 2, 3, 4, 5, 6}));
  }
  ASSERT_TRUE(collector.waitForCount(kUploads));
  {
    std::lock_guard lock(collector.mutex);
    for (int i = 0; i < kUploads; ++i) {
      EXPECT_EQ(collector.slices[i].sequence, static_cast<std::uint64_t>(i + 1));
      EXPECT_EQ(collector.slices[i].upload_sequence, static_cast<std::uint64_t>(i + 1));
      EXPECT_EQ(collector.slices[i].points_upserted.size(), 20u);
    }
  }
  EXPECT_TRUE(test::eventually([&] { return client.lastAppliedSlice() == kUploads; }));

  // Later uploads carry the client's acknowledgement, so the server can let old slices go.
  client.uploadKeyFrame(test::sampleUpload(0, 10, 0, rng));
  ASSERT_TRUE(client.flushUploads(10s));
  ASSERT_TRUE(log->waitFor([](auto& l) { return l.upload_sequences.size() == kUploads + 1; }));
  {
    std::lock_guard lock(log->mutex);
    EXPECT_EQ(log->acknowledged_slices.back(), static_cast<std::uint64_t>(kUploads));
  }
  const EdgeClientCounters counters = client.counters();
  EXPECT_EQ(counters.uploads_sent, kUploads + 1u);
  EXPECT_EQ(counters.uploads_dropped, 0u);
  // Half the keypoints name points the edge has: only the other half's descriptors travel.
  EXPECT_GT(counters.uplink_bytes, kUploads * 150u * 32u);
  EXPECT_GT(counters.downlink_bytes, kUploads * 20u * 60u);
  const std::vector<SessionStats> stats = server->sessions();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].keyframes, kUploads + 1u);
  EXPECT_GE(stats[0].slices_acknowledged, static_cast<std::uint64_t>(kUploads));
  EXPECT_GT(stats[0].uplink_bytes, kUploads * 150u * 32u);
  EXPECT_GT(stats[0].downlink_bytes, kUploads * 20u * 60u);
}

TEST_F(EdgeLoopback, ProbeEchoesTheAskedSizes) {
  EdgeClient client(server->address(), test::sampleSessionConfig(), clientOptions());
  const auto small = client.probe(0, 0);
  ASSERT_TRUE(small.has_value());
  const auto big = client.probe(100000, 300000);
  ASSERT_TRUE(big.has_value());
  EXPECT_GE(big->sent_bytes, 100000u);
  EXPECT_LT(big->sent_bytes, 100100u);
  EXPECT_GE(big->received_bytes, 300000u);
  EXPECT_LT(big->received_bytes, 300100u);
  EXPECT_GT(big->round_trip_ms, 0.0);
  EXPECT_GT(big->server_time_ns, 0u);
  EXPECT_THROW(client.probe(10, 100u << 20), EdgeClientError);  // beyond the server's limit
}

TEST_F(EdgeLoopback, TwoSessionsGetDistinctOrigins) {
  SessionConfig wants_seven = test::sampleSessionConfig("a");
  wants_seven.id_origin = 7;
  EdgeClient a(server->address(), wants_seven, clientOptions());
  SessionConfig also_seven = test::sampleSessionConfig("b");
  also_seven.id_origin = 7;
  EdgeClient b(server->address(), also_seven, clientOptions());
  EXPECT_EQ(a.idOrigin(), 7) << "a free preferred origin is granted";
  EXPECT_NE(b.idOrigin(), a.idOrigin());
  EXPECT_GE(b.idOrigin(), 1);
  EXPECT_NE(a.sessionId(), b.sessionId());
  EXPECT_EQ(server->sessionCount(), 2u);
  a.close();
  EXPECT_TRUE(test::eventually([&] { return server->sessionCount() == 1; }));
}

TEST_F(EdgeLoopback, OffloadFrameReturnsThePose) {
  EdgeClient client(server->address(), test::sampleSessionConfig(), clientOptions());
  const auto result = client.offloadFrame({41, 1.5, "jpeg", test::sampleFrameImage(), "", {}});
  ASSERT_TRUE(result.has_value());
  EXPECT_EQ(result->frame_index, 41u);
  EXPECT_EQ(result->state, OffloadTrackingState::kOk);
  ASSERT_TRUE(result->T_cw.has_value());
  EXPECT_EQ(result->T_cw->translation().x(), 41.0);
  EXPECT_THROW(client.offloadFrame({42, 1.6, "tiff", {1}, "", {}}), EdgeClientError);
}

TEST(EdgeServerOffload, BackendWithoutOffloadAnswersUnimplemented) {
  EdgeServer server("127.0.0.1:0", std::make_shared<FakeFactory>(false));
  EdgeClientOptions options;
  options.connect_timeout = 10s;
  EdgeClient client(server.address(), test::sampleSessionConfig(), options);
  try {
    client.offloadFrame({1, 0.0, "jpeg", test::sampleFrameImage(), "", {}});
    ADD_FAILURE() << "no error";
  } catch (const EdgeClientError& e) {
    EXPECT_THAT(e.what(), HasSubstr("do not track whole frames"));
  }
}

TEST_F(EdgeLoopback, UnknownProtocolVersionIsFailedPrecondition) {
  auto stub = rawStub(server->address());
  v1::OpenSessionRequest open;
  toProto(test::sampleSessionConfig(), &open);
  *open.mutable_header() = headerFor(0, 2);
  v1::OpenSessionReply open_reply;
  grpc::ClientContext context;
  const grpc::Status status = stub->OpenSession(&context, open, &open_reply);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(status.error_message(), HasSubstr("protocol version 2 is not supported"));
  EXPECT_THAT(status.error_message(), HasSubstr("speaks edgeslam.v1 protocol version 1"));

  const std::uint64_t session = openRawSession(*stub);
  v1::UploadKeyFrameRequest upload;
  *upload.mutable_header() = headerFor(session, 0);
  const grpc::Status no_version = rawUpload(*stub, upload);
  EXPECT_EQ(no_version.error_code(), grpc::StatusCode::FAILED_PRECONDITION);
  EXPECT_THAT(no_version.error_message(), HasSubstr("carries no version"));
}

TEST_F(EdgeLoopback, MalformedUploadIsInvalidArgumentAndUnknownSessionNotFound) {
  auto stub = rawStub(server->address());
  const std::uint64_t session = openRawSession(*stub);
  std::mt19937 rng(22);
  v1::UploadKeyFrameRequest request;
  *request.mutable_header() = headerFor(session);
  toProto(test::sampleUpload(1, 20, 0, rng), request.mutable_upload());
  request.mutable_upload()->mutable_keyframe()->mutable_features()->mutable_descriptors()->resize(
      5);
  const grpc::Status status = rawUpload(*stub, request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::INVALID_ARGUMENT);
  EXPECT_THAT(status.error_message(), HasSubstr("descriptors hold 5 bytes"));

  request.mutable_header()->set_session_id(session + 1);
  const grpc::Status unknown = rawUpload(*stub, request);
  EXPECT_EQ(unknown.error_code(), grpc::StatusCode::NOT_FOUND);
  EXPECT_THAT(unknown.error_message(), HasSubstr("open a new session"));
  ASSERT_TRUE(factory->session(0)->waitFor([](auto& l) { return l.upload_sequences.empty(); }));
}

TEST_F(EdgeLoopback, OversizedMessageIsResourceExhaustedAndTheServerGoesOn) {
  auto stub = rawStub(server->address());
  const std::uint64_t session = openRawSession(*stub);
  std::mt19937 rng(23);
  v1::UploadKeyFrameRequest request;
  *request.mutable_header() = headerFor(session);
  KeyFrameUpload upload = test::sampleUpload(1, 20, 0, rng);
  upload.image_bytes.assign(2u << 20, 0x5a);  // 2 MB against a 1 MB limit
  toProto(upload, request.mutable_upload());
  const grpc::Status status = rawUpload(*stub, request);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED) << status.error_message();

  upload.image_bytes = test::sampleKeyFrameImage(1000);
  request.mutable_upload()->set_image(
      std::string(upload.image_bytes.begin(), upload.image_bytes.end()));
  const grpc::Status next = rawUpload(*stub, request);
  EXPECT_TRUE(next.ok()) << next.error_message();
  auto log = factory->session(0);
  ASSERT_TRUE(log->waitFor([](auto& l) { return l.upload_sequences.size() == 1; }));
}

TEST_F(EdgeLoopback, RetriedUploadIsPassedOnOnce) {
  auto stub = rawStub(server->address());
  const std::uint64_t session = openRawSession(*stub);
  std::mt19937 rng(24);
  v1::UploadKeyFrameRequest request;
  *request.mutable_header() = headerFor(session);
  toProto(test::sampleUpload(5, 10, 0, rng), request.mutable_upload());
  EXPECT_TRUE(rawUpload(*stub, request).ok());
  EXPECT_TRUE(rawUpload(*stub, request).ok());
  const auto stats = server->sessions();
  ASSERT_EQ(stats.size(), 1u);
  EXPECT_EQ(stats[0].keyframes, 1u);
  EXPECT_EQ(stats[0].duplicate_uploads, 1u);
}

TEST_F(EdgeLoopback, DroppedSlicesAskForAFullResync) {
  auto stub = rawStub(server->address());
  const std::uint64_t session = openRawSession(*stub);
  auto log = factory->session(0);
  for (int i = 0; i < 10; ++i) log->sink->push(MapSlice{});  // server keeps only 4
  v1::StreamSlicesRequest request;
  *request.mutable_header() = headerFor(session);
  request.set_from_sequence(1);
  {
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + 10s);
    auto reader = stub->StreamSlices(&context, request);
    v1::MapSlice slice;
    EXPECT_FALSE(reader->Read(&slice));
    const grpc::Status status = reader->Finish();
    EXPECT_EQ(status.error_code(), grpc::StatusCode::OUT_OF_RANGE);
    EXPECT_THAT(status.error_message(), HasSubstr("full resync"));
  }
  request.set_want_full_resync(true);
  grpc::ClientContext context;
  context.set_deadline(std::chrono::system_clock::now() + 10s);
  auto reader = stub->StreamSlices(&context, request);
  std::vector<v1::MapSlice> received;
  v1::MapSlice slice;
  while (reader->Read(&slice)) {
    received.push_back(slice);
    if (slice.full_resync()) break;
  }
  context.TryCancel();
  (void)reader->Finish();
  ASSERT_FALSE(received.empty());
  EXPECT_GE(received.front().sequence(), 7u) << "resumes at the oldest slice still kept";
  EXPECT_TRUE(received.back().full_resync());
  EXPECT_EQ(received.back().sequence(), 11u);
  for (std::size_t i = 1; i < received.size(); ++i) {
    EXPECT_EQ(received[i].sequence(), received[i - 1].sequence() + 1);
  }
}

}  // namespace
}  // namespace edgeslam
