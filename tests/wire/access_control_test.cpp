// Client tokens, map grants and per-client limits on a real in-process edge server (plaintext on
// loopback; TLS is covered end to end by tests/cli/server_security_test.cpp).
#include <gmock/gmock.h>
#include <grpcpp/grpcpp.h>
#include <gtest/gtest.h>

#include <random>
#include <sstream>
#include <thread>

#include "edgeslam/v1/edgeslam.grpc.pb.h"
#include "fake_edge_backend.h"
#include "net_test_records.h"
#include "wire/access_tokens.h"
#include "wire/edge_client.h"
#include "wire/edge_server.h"
#include "wire/session_registry.h"
#include "wire/wire_convert.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;
using test::FakeFactory;
using ::testing::HasSubstr;

constexpr const char* kAlice = "alice-0123456789abcdef";
constexpr const char* kBob = "bob-0123456789abcdef-limited";

AccessTokens parseTokens(const std::string& text) {
  std::istringstream in(text);
  return AccessTokens::parse(in, "tokens.txt");
}

std::string parseError(const std::string& text) {
  try {
    parseTokens(text);
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "parsed";
}

TEST(AccessTokens, ParsesTokensAndMapGrants) {
  const AccessTokens tokens =
      parseTokens(std::string("# clients\n\n") + kAlice + "\n" + kBob + " office,lab \r\n");
  EXPECT_EQ(tokens.size(), 2U);
  const AccessGrant* alice = tokens.find(kAlice);
  ASSERT_NE(alice, nullptr);
  EXPECT_TRUE(alice->permitsMap("anything"));
  EXPECT_THAT(alice->label, HasSubstr("token #1 (tokens.txt:3)"));
  EXPECT_EQ(alice->label.find(kAlice), std::string::npos);  // never the secret in logs
  const AccessGrant* bob = tokens.find(kBob);
  ASSERT_NE(bob, nullptr);
  EXPECT_TRUE(bob->permitsMap("lab"));
  EXPECT_FALSE(bob->permitsMap("default"));
  EXPECT_EQ(tokens.find("alice-0123456789abcdeX"), nullptr);
  EXPECT_EQ(tokens.find(""), nullptr);

  EXPECT_THAT(parseError(""), HasSubstr("tokens.txt holds no token"));
  EXPECT_THAT(parseError("short\n"), HasSubstr("tokens.txt line 1: a token has at least 16"));
  EXPECT_THAT(parseError(std::string(kAlice) + "\n" + kAlice + "\n"),
              HasSubstr("line 2: the token is listed twice"));
  EXPECT_THAT(parseError(std::string(kAlice) + " a,,b\n"), HasSubstr("empty map name"));
  EXPECT_THAT(parseError(std::string(kAlice) + " a b\n"), HasSubstr("found more"));

  EXPECT_EQ(bearerToken("Bearer abc"), "abc");
  EXPECT_EQ(bearerToken("Basic abc"), "");
  EXPECT_EQ(bearerToken("Bearer "), "");
}

TEST(AccessTokens, LoopbackAddresses) {
  for (const char* address :
       {"127.0.0.1:50051", "127.1.2.3:0", "localhost:1", "[::1]:50051", "unix:/tmp/edge.sock"}) {
    EXPECT_TRUE(isLoopbackAddress(address)) << address;
  }
  for (const char* address : {"0.0.0.0:50051", "[::]:1", "192.168.1.2:5", "edge.example:1",
                              "127.0.0.1.example.com:1", "1270.0.0.1:5"}) {
    EXPECT_FALSE(isLoopbackAddress(address)) << address;
  }
}

TEST(UploadRate, AdmitsABurstThenTheRate) {
  UploadRate rate;
  const auto start = std::chrono::steady_clock::now();
  int admitted = 0;
  for (int i = 0; i < 20; ++i) admitted += rate.admit(10.0, start) ? 1 : 0;
  EXPECT_EQ(admitted, 10);
  EXPECT_FALSE(rate.admit(10.0, start + 50ms));
  EXPECT_TRUE(rate.admit(10.0, start + 150ms));
  EXPECT_TRUE(UploadRate{}.admit(0.0, start));  // no limit
}

class AccessControl : public ::testing::Test {
 protected:
  void startServer(EdgeServerLimits limits = {}) {
    factory_ = std::make_shared<FakeFactory>();
    EdgeServerSecurity security;
    security.tokens = std::make_shared<const AccessTokens>(
        parseTokens(std::string(kAlice) + "\n" + kBob + " lab\n"));
    server_ = std::make_unique<EdgeServer>("127.0.0.1:0", factory_, limits, security);
    stub_ = v1::EdgeSlam::NewStub(
        grpc::CreateChannel(server_->address(), grpc::InsecureChannelCredentials()));
  }

  static void authorize(grpc::ClientContext& context, const std::string& token,
                        const std::string& map) {
    if (!token.empty()) context.AddMetadata("authorization", "Bearer " + token);
    if (!map.empty()) context.AddMetadata("edgeslam-map", map);
    context.set_deadline(std::chrono::system_clock::now() + 10s);
  }

  grpc::Status open(const std::string& token, const std::string& map = "",
                    std::uint64_t* session = nullptr) {
    v1::OpenSessionRequest request;
    toProto(test::sampleSessionConfig("access"), &request);
    request.mutable_header()->set_protocol_version(kWireProtocolVersion);
    v1::OpenSessionReply reply;
    grpc::ClientContext context;
    authorize(context, token, map);
    const grpc::Status status = stub_->OpenSession(&context, request, &reply);
    if (session != nullptr) *session = reply.session_id();
    return status;
  }

  grpc::Status upload(const std::string& token, std::uint64_t session, std::uint64_t sequence) {
    std::mt19937 rng(static_cast<unsigned>(sequence));
    v1::UploadKeyFrameRequest request;
    request.mutable_header()->set_protocol_version(kWireProtocolVersion);
    request.mutable_header()->set_session_id(session);
    toProto(test::sampleUpload(sequence, 10, 0, rng), request.mutable_upload());
    v1::UploadKeyFrameReply reply;
    grpc::ClientContext context;
    authorize(context, token, "");
    return stub_->UploadKeyFrame(&context, request, &reply);
  }

  grpc::Status probe(const std::string& token) {
    v1::ProbeRequest request;
    request.mutable_header()->set_protocol_version(kWireProtocolVersion);
    v1::ProbeReply reply;
    grpc::ClientContext context;
    authorize(context, token, "");
    return stub_->Probe(&context, request, &reply);
  }

  std::shared_ptr<FakeFactory> factory_;
  std::unique_ptr<EdgeServer> server_;
  std::unique_ptr<v1::EdgeSlam::Stub> stub_;
};

TEST_F(AccessControl, EveryCallWantsAKnownToken) {
  startServer();
  grpc::Status status = open("");
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("wants a client token"));
  status = open("mallory-0123456789abcdef");
  EXPECT_EQ(status.error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_THAT(status.error_message(), HasSubstr("not known"));
  EXPECT_EQ(probe("").error_code(), grpc::StatusCode::UNAUTHENTICATED);
  EXPECT_TRUE(probe(kAlice).ok());
  EXPECT_EQ(factory_->opened(), 0U);

  std::uint64_t session = 0;
  ASSERT_TRUE(open(kAlice, "", &session).ok());
  EXPECT_TRUE(upload(kAlice, session, 1).ok());
  EXPECT_EQ(upload("", session, 2).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  // Another client may not use (or learn anything from) Alice's session.
  status = upload(kBob, session, 2);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(status.error_message(), HasSubstr("belongs to another client"));
}

TEST_F(AccessControl, ATokenLimitedToMapsOpensSessionsOnThoseOnly) {
  startServer();
  grpc::Status status = open(kBob);  // the default map
  EXPECT_EQ(status.error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_THAT(status.error_message(), HasSubstr("map 'default'"));
  EXPECT_EQ(open(kBob, "office").error_code(), grpc::StatusCode::PERMISSION_DENIED);
  EXPECT_TRUE(open(kBob, "lab").ok());
  EXPECT_TRUE(open(kAlice, "office").ok());
}

TEST_F(AccessControl, SessionsPerTokenAreLimited) {
  EdgeServerLimits limits;
  limits.max_sessions_per_client = 2;
  startServer(limits);
  std::uint64_t first = 0;
  ASSERT_TRUE(open(kAlice, "", &first).ok());
  ASSERT_TRUE(open(kAlice).ok());
  const grpc::Status status = open(kAlice);
  EXPECT_EQ(status.error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  EXPECT_THAT(status.error_message(), HasSubstr("maximum of 2 sessions"));
  EXPECT_TRUE(open(kBob, "lab").ok());  // other clients are not held back

  // Closing one frees its place.
  v1::CloseSessionRequest close;
  close.mutable_header()->set_protocol_version(kWireProtocolVersion);
  close.mutable_header()->set_session_id(first);
  v1::CloseSessionReply closed;
  grpc::ClientContext context;
  authorize(context, kAlice, "");
  ASSERT_TRUE(stub_->CloseSession(&context, close, &closed).ok());
  EXPECT_TRUE(open(kAlice).ok());
}

TEST_F(AccessControl, UnusedSessionsDoNotLockOthersOut) {
  EdgeServerLimits limits;
  limits.max_sessions = 4;
  limits.reclaim_idle_after = 1000ms;
  limits.max_sessions_per_client = 255;
  startServer(limits);
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(open(kAlice).ok());
  // Full, and every session was used just now: refused.
  EXPECT_EQ(open(kBob, "lab").error_code(), grpc::StatusCode::RESOURCE_EXHAUSTED);
  std::this_thread::sleep_for(1500ms);
  // The idle ones make room, one at a time, long before the idle timeout (60 s).
  EXPECT_TRUE(open(kBob, "lab").ok());
  EXPECT_EQ(server_->sessionCount(), 4U);
}

TEST_F(AccessControl, UploadsOverTheRateAreResourceExhausted) {
  EdgeServerLimits limits;
  limits.max_uploads_per_second = 5.0;
  startServer(limits);
  std::uint64_t session = 0;
  ASSERT_TRUE(open(kAlice, "", &session).ok());
  int refused = 0;
  for (std::uint64_t sequence = 1; sequence <= 12; ++sequence) {
    const grpc::Status status = upload(kAlice, session, sequence);
    if (status.error_code() == grpc::StatusCode::RESOURCE_EXHAUSTED) {
      ++refused;
      EXPECT_THAT(status.error_message(), HasSubstr("more than 5 uploads"));
    }
  }
  EXPECT_GE(refused, 5);  // 5 in the burst, maybe one more as time passes
  EXPECT_LE(refused, 7);
}

TEST_F(AccessControl, TheClientSendsItsToken) {
  startServer();
  EdgeClientOptions options;
  options.connect_timeout = 10s;
  options.credentials.token = kAlice;
  EdgeClient client(server_->address(), test::sampleSessionConfig("with token"), options);
  EXPECT_TRUE(client.probe(100, 100).has_value());
  options.credentials.token = "mallory-0123456789abcdef";
  try {
    EdgeClient refused(server_->address(), test::sampleSessionConfig("wrong token"), options);
    ADD_FAILURE() << "a wrong token was let in";
  } catch (const EdgeClientError& e) {
    EXPECT_THAT(e.what(), HasSubstr("not known"));
  }
}

}  // namespace
}  // namespace edgeslam
