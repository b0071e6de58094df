// The client tells its owner which keyframe an upload it gave up on carried: pushed out of the
// full queue, or refused by the server.
#include <gtest/gtest.h>

#include <condition_variable>
#include <memory>
#include <mutex>
#include <random>
#include <stdexcept>
#include <utility>
#include <vector>

#include "fake_edge_backend.h"
#include "net_test_records.h"
#include "wire/edge_client.h"
#include "wire/edge_server.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;

// Holds every keyframe upload in the backend until opened, so that the client's queue fills up
// behind the one in flight; refuses the keyframe `poisoned`.
struct Gate {
  std::mutex mutex;
  std::condition_variable changed;
  bool open = false;
  KeyFrameId poisoned = kInvalidId;
  std::vector<std::uint64_t> received;  // sequences that reached the backend

  void release() {
    {
      std::lock_guard lock(mutex);
      open = true;
    }
    changed.notify_all();
  }
  bool waitForReceived(std::size_t count) {
    std::unique_lock lock(mutex);
    return changed.wait_for(lock, 10s, [&] { return received.size() >= count; });
  }
};

class GatedBackend final : public EdgeSessionBackend {
 public:
  GatedBackend(std::shared_ptr<Gate> gate, SliceSink& sink) : gate_(std::move(gate)), sink_(sink) {}

  void onKeyFrame(KeyFrameUpload upload) override {
    {
      std::unique_lock lock(gate_->mutex);
      gate_->received.push_back(upload.sequence);
      gate_->changed.notify_all();
      gate_->changed.wait(lock, [&] { return gate_->open; });
      if (upload.keyframe.id == gate_->poisoned) throw std::runtime_error("poisoned keyframe");
    }
    MapSlice slice;
    slice.upload_sequence = upload.sequence;
    slice.processed_keyframe = upload.keyframe.id;
    sink_.push(std::move(slice));
  }

 private:
  std::shared_ptr<Gate> gate_;
  SliceSink& sink_;
};

class GatedFactory final : public EdgeSessionFactory {
 public:
  explicit GatedFactory(std::shared_ptr<Gate> gate) : gate_(std::move(gate)) {}
  std::unique_ptr<EdgeSessionBackend> open(const SessionConfig& /*config*/,
                                           SliceSink& sink) override {
    return std::make_unique<GatedBackend>(gate_, sink);
  }

 private:
  std::shared_ptr<Gate> gate_;
};

struct DropLog {
  std::mutex mutex;
  std::vector<std::pair<std::uint64_t, KeyFrameId>> dropped;

  std::function<void(std::uint64_t, KeyFrameId)> callback() {
    return [this](std::uint64_t sequence, KeyFrameId keyframe) {
      std::lock_guard lock(mutex);
      dropped.emplace_back(sequence, keyframe);
    };
  }
  std::vector<std::pair<std::uint64_t, KeyFrameId>> snapshot() {
    std::lock_guard lock(mutex);
    return dropped;
  }
};

class UploadDropped : public ::testing::Test {
 protected:
  void SetUp() override {
    gate = std::make_shared<Gate>();
    server = std::make_unique<EdgeServer>("127.0.0.1:0", std::make_shared<GatedFactory>(gate));
  }
  void TearDown() override {
    gate->release();  // the server cannot stop while a call waits in the backend
    if (client) client->close();
    server.reset();
  }

  void connect(std::size_t queue_capacity) {
    EdgeClientOptions options;
    options.connect_timeout = 10s;
    options.upload_queue_capacity = queue_capacity;
    options.on_upload_dropped = log.callback();
    client = std::make_unique<EdgeClient>(server->address(), test::sampleSessionConfig(), options);
  }

  KeyFrameId keyframeId(std::uint64_t local) const {
    return test::clientId(client->idOrigin(), local);
  }

  std::uint64_t upload(std::uint64_t local_keyframe) {
    KeyFrameUpload u = test::sampleUpload(0, 10, 0, rng);
    u.keyframe.id = keyframeId(local_keyframe);
    return client->uploadKeyFrame(std::move(u));
  }

  std::shared_ptr<Gate> gate;
  std::unique_ptr<EdgeServer> server;
  std::unique_ptr<EdgeClient> client;
  DropLog log;
  std::mt19937 rng{31};
};

TEST_F(UploadDropped, QueueOverflowReportsTheOldestQueuedUploadsKeyFrame) {
  connect(2);
  EXPECT_EQ(upload(101), 1u);
  ASSERT_TRUE(gate->waitForReceived(1));  // upload 1 is held in the backend: 2 may wait
  EXPECT_EQ(upload(102), 2u);
  EXPECT_EQ(upload(103), 3u);
  EXPECT_TRUE(log.snapshot().empty());
  EXPECT_EQ(upload(104), 4u);  // pushes out 2
  EXPECT_EQ(upload(105), 5u);  // pushes out 3
  // Reported on the caller's thread before uploadKeyFrame returned.
  const std::vector<std::pair<std::uint64_t, KeyFrameId>> expected = {{2, keyframeId(102)},
                                                                      {3, keyframeId(103)}};
  EXPECT_EQ(log.snapshot(), expected);
  const EdgeClientCounters counters = client->counters();
  EXPECT_EQ(counters.uploads_dropped, 2u);
  EXPECT_EQ(counters.uploads_overflowed, 2u);

  gate->release();
  ASSERT_TRUE(client->flushUploads(10s));
  {
    std::lock_guard lock(gate->mutex);
    EXPECT_EQ(gate->received, (std::vector<std::uint64_t>{1, 4, 5}));
  }
  EXPECT_EQ(log.snapshot(), expected) << "uploads that went through are not reported";
  EXPECT_EQ(client->counters().uploads_sent, 3u);
}

TEST_F(UploadDropped, RejectedUploadIsReportedBeforeTheFlushEnds) {
  connect(8);
  gate->poisoned = keyframeId(202);
  gate->release();
  upload(201);
  upload(202);
  upload(203);
  ASSERT_TRUE(client->flushUploads(10s));
  const std::vector<std::pair<std::uint64_t, KeyFrameId>> expected = {{2, keyframeId(202)}};
  EXPECT_EQ(log.snapshot(), expected);
  const EdgeClientCounters counters = client->counters();
  EXPECT_EQ(counters.uploads_rejected, 1u);
  EXPECT_EQ(counters.uploads_overflowed, 0u);
  EXPECT_EQ(counters.uploads_sent, 2u);
}

TEST_F(UploadDropped, UploadsDiscardedByCloseAreNotReported) {
  connect(4);
  upload(301);
  ASSERT_TRUE(gate->waitForReceived(1));
  upload(302);
  upload(303);
  gate->release();
  client->close();
  EXPECT_TRUE(log.snapshot().empty());
}

}  // namespace
}  // namespace edgeslam
