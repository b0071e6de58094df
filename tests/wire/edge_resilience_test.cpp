// The wire when things go wrong: absent server, clients that vanish, a server restart, closing
// while the server is gone. Generous timeouts; nothing here asserts tight timings.
#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <condition_variable>
#include <mutex>
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

// A port nothing listens on (bound once, then released).
int freePort() {
  EdgeServer probe("127.0.0.1:0", std::make_shared<FakeFactory>());
  const int port = probe.port();
  probe.shutdown();
  return port;
}

EdgeClientOptions quickOptions(SliceCollector* collector = nullptr) {
  EdgeClientOptions options;
  options.connect_timeout = 10s;
  options.rpc_timeout = 2s;
  options.backoff_initial = 50ms;
  options.backoff_max = 300ms;
  if (collector != nullptr) options.on_slice = collector->callback();
  return options;
}

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

TEST(EdgeResilience, AbsentServerGivesAClearErrorInTime) {
  const std::string address = "127.0.0.1:" + std::to_string(freePort());
  EdgeClientOptions options;
  options.connect_timeout = 300ms;
  const auto start = std::chrono::steady_clock::now();
  try {
    EdgeClient client(address, test::sampleSessionConfig(), options);
    ADD_FAILURE() << "connected to nothing";
  } catch (const EdgeClientError& e) {
    EXPECT_THAT(e.what(), HasSubstr(address));
    EXPECT_THAT(e.what(), HasSubstr("not reachable"));
  }
  EXPECT_LT(secondsSince(start), 5.0);
}

TEST(EdgeResilience, ClientVanishingMidStreamDoesNotHurtTheServer) {
  auto factory = std::make_shared<FakeFactory>();
  EdgeServerLimits limits;
  limits.idle_timeout = 500ms;
  EdgeServer server("127.0.0.1:0", factory, limits);
  std::uint64_t vanished_session = 0;
  {
    // A raw client: opens a session, reads one slice of its stream, then disappears without
    // closing anything.
    auto channel = grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials());
    auto stub = v1::EdgeSlam::NewStub(channel);
    v1::OpenSessionRequest open;
    toProto(test::sampleSessionConfig("vanishing"), &open);
    open.mutable_header()->set_protocol_version(kWireProtocolVersion);
    v1::OpenSessionReply opened;
    grpc::ClientContext open_context;
    ASSERT_TRUE(stub->OpenSession(&open_context, open, &opened).ok());
    vanished_session = opened.session_id();
    factory->session(0)->sink->push(MapSlice{});
    factory->session(0)->sink->push(MapSlice{});
    v1::StreamSlicesRequest request;
    request.mutable_header()->set_protocol_version(kWireProtocolVersion);
    request.mutable_header()->set_session_id(vanished_session);
    request.set_from_sequence(1);
    grpc::ClientContext context;
    auto reader = stub->StreamSlices(&context, request);
    v1::MapSlice slice;
    ASSERT_TRUE(reader->Read(&slice));
    EXPECT_EQ(slice.sequence(), 1u);
    context.TryCancel();
    // reader, stub and channel go out of scope here
  }
  // The server goes on serving others...
  SliceCollector collector;
  EdgeClient other(server.address(), test::sampleSessionConfig("other"), quickOptions(&collector));
  std::mt19937 rng(31);
  other.uploadKeyFrame(test::sampleUpload(0, 50, 3, rng));
  ASSERT_TRUE(collector.waitForCount(1));
  // ...and lets the vanished session go once it has been silent for the idle timeout.
  auto vanished_log = factory->session(0);
  ASSERT_TRUE(vanished_log->waitFor([](auto& l) { return l.destroyed; }));
  EXPECT_GE(server.idleSessionsClosed(), 1u);
  const auto sessions = server.sessions();
  ASSERT_EQ(sessions.size(), 1u);
  EXPECT_EQ(sessions[0].client_name, "other");
  EXPECT_NE(sessions[0].session_id, vanished_session);
  EXPECT_TRUE(sessions[0].streaming);
}

TEST(EdgeResilience, ClientReconnectsAndResumesAfterAServerRestart) {
  auto first_factory = std::make_shared<FakeFactory>();
  auto server = std::make_unique<EdgeServer>("127.0.0.1:0", first_factory);
  const int port = server->port();
  const std::string address = server->address();

  SliceCollector collector;
  std::mutex events_mutex;
  std::vector<EdgeSessionEvent> events;
  EdgeClientOptions options = quickOptions(&collector);
  options.upload_queue_capacity = 4;
  options.on_session_event = [&](const EdgeSessionEvent& event) {
    std::lock_guard lock(events_mutex);
    events.push_back(event);
  };
  EdgeClient client(address, test::sampleSessionConfig(), options);
  const std::uint8_t origin = client.idOrigin();
  std::mt19937 rng(32);
  for (int i = 0; i < 3; ++i) client.uploadKeyFrame(test::sampleUpload(0, 50, 2, rng));
  ASSERT_TRUE(collector.waitForCount(3));
  ASSERT_TRUE(test::eventually([&] { return client.lastAppliedSlice() == 3; }));

  server->shutdown();
  server.reset();
  // While the server is away, uploads pile up: four waiting (and perhaps one being retried), the
  // older ones dropped.
  for (int i = 0; i < 10; ++i) client.uploadKeyFrame(test::sampleUpload(0, 50, 2, rng));
  EXPECT_TRUE(test::eventually([&] { return client.counters().uploads_dropped >= 5; }));
  EXPECT_LE(client.pendingUploads(), 5u);

  auto second_factory = std::make_shared<FakeFactory>();
  EdgeServer restarted("127.0.0.1:" + std::to_string(port), second_factory);
  // The client finds the session gone, opens a new one (keeping its id origin), asks for a full
  // resync, and its queued uploads reach the new session.
  auto log = second_factory->session(0, 15s);
  ASSERT_NE(log, nullptr);
  EXPECT_EQ(log->config.id_origin, origin);
  ASSERT_TRUE(collector.waitForSlice([](const MapSlice& s) { return s.full_resync; }, 15s));
  ASSERT_TRUE(client.flushUploads(15s));
  // The four newest uploads always survive (plus the one in flight, if the worker had taken it).
  ASSERT_TRUE(log->waitFor([](auto& l) { return l.upload_sequences.size() >= 4; }, 15s));
  {
    std::lock_guard lock(log->mutex);
    EXPECT_TRUE(std::is_sorted(log->upload_sequences.begin(), log->upload_sequences.end()));
    EXPECT_EQ(log->upload_sequences.back(), 13u);
    EXPECT_GE(log->resync_requests, 1);
  }
  EXPECT_TRUE(test::eventually([&] { return !client.fullResyncPending(); }));
  const EdgeClientCounters counters = client.counters();
  EXPECT_EQ(counters.session_reopens, 1u);
  EXPECT_GE(counters.reconnects, 1u);
  EXPECT_GE(counters.uploads_dropped, 5u);
  EXPECT_EQ(counters.uploads_sent + counters.uploads_dropped, 13u);
  EXPECT_EQ(client.idOrigin(), origin);
  std::lock_guard lock(events_mutex);
  ASSERT_FALSE(events.empty());
  EXPECT_TRUE(events.front().reopened);
  EXPECT_TRUE(events.front().full_resync_needed);
  EXPECT_EQ(events.front().id_origin, origin);
}

// The full resync's slice is the edge's map when the client asked for it; uploads the new session
// takes before the client has applied it are not listed there, yet not lost. Under load the
// client applied the resync 1.3 s after it was made, and re-sent the 16 keyframes the session had
// taken meanwhile (each counted in flight, holding tracking's keyframes back).
TEST(EdgeResilience, UploadsTheNewSessionTookDuringItsResyncAreOnTheirWay) {
  auto server = std::make_unique<EdgeServer>("127.0.0.1:0", std::make_shared<FakeFactory>());
  const int port = server->port();
  std::mutex resync_mutex;
  std::condition_variable resync_changed;
  bool in_resync = false;
  bool release_resync = false;
  EdgeClient* client_ptr = nullptr;
  std::vector<KeyFrameId> on_their_way;
  EdgeClientOptions options = quickOptions();
  options.on_slice = [&](MapSlice slice) {
    if (!slice.full_resync) return;
    std::unique_lock lock(resync_mutex);
    in_resync = true;
    resync_changed.notify_all();
    // A slow applier: the uploads go on meanwhile.
    resync_changed.wait_for(lock, 15s, [&] { return release_resync; });
    on_their_way = client_ptr->pendingUploadKeyFrames();
  };
  EdgeClient client(server->address(), test::sampleSessionConfig(), options);
  client_ptr = &client;
  std::mt19937 rng(19);
  const auto upload = [&](std::uint64_t sequence) {
    KeyFrameUpload u = test::sampleUpload(sequence, 50, 2, rng);
    const KeyFrameId id = u.keyframe.id;
    client.uploadKeyFrame(std::move(u));
    return id;
  };
  upload(1);
  ASSERT_TRUE(client.flushUploads(10s));

  server->shutdown();
  server.reset();
  EdgeServer restarted("127.0.0.1:" + std::to_string(port), std::make_shared<FakeFactory>());
  const KeyFrameId first_after = upload(2);
  {
    std::unique_lock lock(resync_mutex);
    ASSERT_TRUE(resync_changed.wait_for(lock, 15s, [&] { return in_resync; }));
  }
  // While the client applies the resync: the new session takes two more.
  const std::vector<KeyFrameId> taken = {first_after, upload(3), upload(4)};
  ASSERT_TRUE(client.flushUploads(10s));
  EXPECT_EQ(client.pendingUploads(), 0u);
  {
    std::lock_guard lock(resync_mutex);
    release_resync = true;
  }
  resync_changed.notify_all();
  ASSERT_TRUE(test::eventually([&] { return !client.fullResyncPending(); }));
  for (const KeyFrameId id : taken) {
    EXPECT_NE(std::find(on_their_way.begin(), on_their_way.end(), id), on_their_way.end())
        << "keyframe " << id << " taken by the new session during its resync";
  }
  // Once the resync is applied, an upload the session took is no longer pending.
  upload(5);
  ASSERT_TRUE(client.flushUploads(10s));
  EXPECT_TRUE(client.pendingUploadKeyFrames().empty());
}

TEST(EdgeResilience, CloseReturnsPromptly) {
  auto factory = std::make_shared<FakeFactory>();
  auto server = std::make_unique<EdgeServer>("127.0.0.1:0", factory);
  SliceCollector collector;
  EdgeClientOptions options = quickOptions(&collector);
  options.rpc_timeout = 30s;  // close() must not wait for it
  {
    EdgeClient client(server->address(), test::sampleSessionConfig(), options);
    const auto start = std::chrono::steady_clock::now();
    client.close();
    EXPECT_LT(secondsSince(start), 3.0);
    EXPECT_TRUE(factory->session(0)->waitFor([](auto& l) { return l.destroyed; }))
        << "close() ends the session on the server";
  }
  EdgeClient client(server->address(), test::sampleSessionConfig(), options);
  server->shutdown();
  std::mt19937 rng(33);
  for (int i = 0; i < 3; ++i) client.uploadKeyFrame(test::sampleUpload(0, 20, 0, rng));
  std::this_thread::sleep_for(200ms);  // let the worker start retrying against nothing
  const auto start = std::chrono::steady_clock::now();
  client.close();
  EXPECT_LT(secondsSince(start), 3.0);
  client.close();  // idempotent
  EXPECT_EQ(client.pendingUploads(), 0u);
}

TEST(EdgeResilience, ServerShutdownWithClientsConnectedIsPrompt) {
  auto factory = std::make_shared<FakeFactory>();
  EdgeServer server("127.0.0.1:0", factory);
  SliceCollector collector;
  EdgeClient a(server.address(), test::sampleSessionConfig("a"), quickOptions(&collector));
  EdgeClient b(server.address(), test::sampleSessionConfig("b"), quickOptions(&collector));
  ASSERT_TRUE(test::eventually([&] {
    const auto sessions = server.sessions();
    return sessions.size() == 2 && sessions[0].streaming && sessions[1].streaming;
  }));
  const auto start = std::chrono::steady_clock::now();
  server.shutdown();
  EXPECT_LT(secondsSince(start), 5.0);
  EXPECT_EQ(server.sessionCount(), 0u);
}

}  // namespace
}  // namespace edgeslam
