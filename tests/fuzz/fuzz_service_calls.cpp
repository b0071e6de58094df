// Every call of the EdgeSlam gRPC service as a hostile client makes it: a real EdgeServer on
// loopback (the transport's own decoding, the handlers' checks, session lookup, limits), with a
// fake SLAM backend. The first byte picks the call, the rest is its request. Requests that name no
// session are pointed at one the harness keeps open, so mutations reach past the session lookup.
// The control messages (close, probe, stream) are fuzzed here; the payload decoders have their own
// harnesses.
#include <grpcpp/grpcpp.h>

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "edgeslam/v1/edgeslam.grpc.pb.h"
#include "wire/edge_server.h"
#include "wire/fake_edge_backend.h"
#include "wire/net_test_records.h"
#include "wire/wire_convert.h"

namespace {

using namespace edgeslam;

struct Harness {
  std::shared_ptr<test::FakeFactory> factory = std::make_shared<test::FakeFactory>();
  EdgeServer server{"127.0.0.1:0", factory};
  std::unique_ptr<v1::EdgeSlam::Stub> stub = v1::EdgeSlam::NewStub(
      grpc::CreateChannel(server.address(), grpc::InsecureChannelCredentials()));
  std::uint64_t session_id = 0;

  Harness() { reopen(); }

  void reopen() {
    v1::OpenSessionRequest open;
    toProto(test::sampleSessionConfig("fuzz"), &open);
    v1::OpenSessionReply reply;
    grpc::ClientContext context;
    context.set_deadline(std::chrono::system_clock::now() + std::chrono::seconds(5));
    if (stub->OpenSession(&context, open, &reply).ok()) session_id = reply.session_id();
  }
};

Harness& harness() {
  static Harness* h = new Harness();  // lives until exit: the server's threads outlast main
  return *h;
}

template <typename Request>
bool parse(Request& request, const std::uint8_t* data, std::size_t size) {
  if (!request.ParseFromArray(data, static_cast<int>(size))) return false;
  if (request.header().session_id() == 0) {
    request.mutable_header()->set_session_id(harness().session_id);
  }
  return true;
}

void deadline(grpc::ClientContext& context) {
  context.set_deadline(std::chrono::system_clock::now() + std::chrono::milliseconds(200));
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  Harness& h = harness();
  const std::uint8_t call = data[0] % 6;
  ++data;
  --size;
  grpc::ClientContext context;
  deadline(context);
  switch (call) {
    case 0: {
      v1::OpenSessionRequest request;
      v1::OpenSessionReply reply;
      if (!request.ParseFromArray(data, static_cast<int>(size))) return 0;
      if (h.stub->OpenSession(&context, request, &reply).ok()) {
        v1::CloseSessionRequest close;
        close.mutable_header()->set_protocol_version(kWireProtocolVersion);
        close.mutable_header()->set_session_id(reply.session_id());
        v1::CloseSessionReply closed;
        grpc::ClientContext close_context;
        deadline(close_context);
        (void)h.stub->CloseSession(&close_context, close, &closed);
      }
      break;
    }
    case 1: {
      v1::CloseSessionRequest request;
      v1::CloseSessionReply reply;
      if (!parse(request, data, size)) return 0;
      if (h.stub->CloseSession(&context, request, &reply).ok() &&
          request.header().session_id() == h.session_id) {
        h.reopen();
      }
      break;
    }
    case 2: {
      v1::UploadKeyFrameRequest request;
      v1::UploadKeyFrameReply reply;
      if (parse(request, data, size)) (void)h.stub->UploadKeyFrame(&context, request, &reply);
      break;
    }
    case 3: {
      v1::ProbeRequest request;
      v1::ProbeReply reply;
      if (parse(request, data, size)) (void)h.stub->Probe(&context, request, &reply);
      break;
    }
    case 4: {
      v1::OffloadFrameRequest request;
      v1::OffloadFrameReply reply;
      if (parse(request, data, size)) (void)h.stub->OffloadFrame(&context, request, &reply);
      break;
    }
    default: {
      v1::StreamSlicesRequest request;
      if (!parse(request, data, size)) return 0;
      auto reader = h.stub->StreamSlices(&context, request);
      v1::MapSlice slice;
      for (int i = 0; i < 4 && reader->Read(&slice); ++i) {
      }
      context.TryCancel();
      (void)reader->Finish();
      break;
    }
  }
  return 0;
}
