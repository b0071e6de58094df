#include "io/live_camera.h"

#include <gtest/gtest.h>

#include <atomic>
#include <mutex>
#include <stdexcept>
#include <vector>

namespace edgeslam {
namespace {

// A camera clock that moves only when someone sleeps or reads a frame.
struct FakeClock {
  std::atomic<double> now = 0.0;
  void advance(double ms) { now.store(now.load() + ms); }
  LiveCameraClock clock() {
    return {.now_ms = [this] { return now.load(); },
            .sleep_ms =
                [this](double ms) {
                  if (ms > 0.0) advance(ms);
                }};
  }
};

// Reading on the consumer's thread: each read moves the fake clock, deterministically.
constexpr LiveCameraOptions kReadWhenTaken{.read_ahead = false};

// Frames at 30 fps whose grey image is empty; each read costs `read_ms` on the fake clock and is
// recorded, so a test sees which frames were decoded.
class ClockedReader : public DatasetReader {
 public:
  ClockedReader(std::size_t count, FakeClock& clock, double read_ms)
      : camera_(intrinsics()), stamps_(count), truth_(count), clock_(clock), read_ms_(read_ms) {
    info_.frame_count = count;
    for (std::size_t i = 0; i < count; ++i) stamps_[i] = 100.0 + static_cast<double>(i) / 30.0;
  }
  const DatasetInfo& info() const override { return info_; }
  const PinholeCamera& camera() const override { return camera_; }
  const std::vector<double>& timestamps() const override { return stamps_; }
  const std::vector<std::optional<SE3d>>& groundTruth() const override { return truth_; }
  DatasetFrame load(std::size_t index) override {
    clock_.advance(read_ms_);
    const std::lock_guard lock(reads_mutex_);
    reads.push_back(index);
    DatasetFrame frame;
    frame.index = index;
    frame.timestamp = stamps_[index];
    return frame;
  }

  std::vector<std::size_t> reads;

 private:
  static CameraIntrinsics intrinsics() {
    CameraIntrinsics k;
    k.width = k.height = 8;
    k.fx = k.fy = 10.0;
    k.cx = k.cy = 4.0;
    return k;
  }
  DatasetInfo info_;
  PinholeCamera camera_;
  std::vector<double> stamps_;
  std::vector<std::optional<SE3d>> truth_;
  FakeClock& clock_;
  double read_ms_;
  std::mutex reads_mutex_;
};

constexpr double kPeriodMs = 1000.0 / 30.0;

TEST(LiveFrameSchedule, NewestDueFrameFollowsTheCameraClock) {
  const LiveFrameSchedule schedule({5.0, 5.1, 5.2, 5.3}, 4);
  EXPECT_EQ(schedule.newestDue(-1.0), std::nullopt);
  EXPECT_EQ(schedule.newestDue(0.0), 0u);
  EXPECT_EQ(schedule.newestDue(99.0), 0u);
  EXPECT_EQ(schedule.newestDue(100.5), 1u);
  EXPECT_EQ(schedule.newestDue(250.0), 2u);
  EXPECT_EQ(schedule.newestDue(1e9), 3u);
}

TEST(LiveFrameSchedule, AClientAheadWaitsForTheNextFrame) {
  const LiveFrameSchedule schedule({0.0, 0.1, 0.2}, 3);
  const auto first = schedule.next(std::nullopt, 0.0);
  ASSERT_TRUE(first);
  EXPECT_EQ(first->index, 0u);
  EXPECT_EQ(first->skipped, 0u);
  const auto second = schedule.next(0, 30.0);
  ASSERT_TRUE(second);
  EXPECT_EQ(second->index, 1u);
  EXPECT_EQ(second->skipped, 0u);
  EXPECT_NEAR(second->wait_ms, 70.0, 1e-9);
  EXPECT_EQ(schedule.next(2, 1e9), std::nullopt);
}

TEST(LiveFrameSchedule, AClientBehindSkipsToTheNewestDueFrame) {
  const LiveFrameSchedule schedule({0.0, 0.1, 0.2, 0.3, 0.4, 0.5}, 6);
  // Busy with frame 0 until 0.35 s: frames 1 and 2 were due and passed, 3 is the newest.
  const auto pick = schedule.next(0, 350.0);
  ASSERT_TRUE(pick);
  EXPECT_EQ(pick->index, 3u);
  EXPECT_EQ(pick->skipped, 2u);
  EXPECT_EQ(pick->wait_ms, 0.0);
  // Only the played range counts: past it there is nothing newer to skip to.
  const LiveFrameSchedule first_four({0.0, 0.1, 0.2, 0.3, 0.4, 0.5}, 4);
  EXPECT_EQ(first_four.next(0, 1e9)->index, 3u);
}

TEST(LiveFrameSchedule, TimestampsGoingBackNeverRunTheClockBackwards) {
  const LiveFrameSchedule schedule({1.0, 1.2, 1.1, 1.3}, 4);
  EXPECT_NEAR(schedule.dueMs(2), 200.0, 1e-9);
  EXPECT_EQ(schedule.newestDue(250.0), 2u);
  EXPECT_THROW(LiveFrameSchedule({1.0}, 2), std::invalid_argument);
}

TEST(LiveCamera, AFastClientGetsEveryFrameAtItsDueTime) {
  FakeClock clock;
  ClockedReader reader(10, clock, 5.0);
  LiveCamera camera(reader, 10, clock.clock(), kReadWhenTaken);
  std::size_t expected = 0;
  while (auto frame = camera.grab()) {
    EXPECT_EQ(frame->index, expected);
    EXPECT_EQ(frame->skipped, 0u);
    // Read in the wait before it was due, handed over at its time: the read is no latency.
    EXPECT_NEAR(clock.now, std::max(frame->due_ms, 5.0), 1e-9);
    EXPECT_NEAR(frame->load_ms, 5.0, 1e-9);
    clock.advance(10.0);  // tracking, well inside the frame period
    ++expected;
  }
  EXPECT_EQ(expected, 10u);
  EXPECT_EQ(camera.skipped(), 0u);
  EXPECT_EQ(reader.reads.size(), 10u);
}

TEST(LiveCamera, AStarvedClientSkipsToTheNewestDueFrameAndNeverReadsTheSkippedOnes) {
  FakeClock clock;
  ClockedReader reader(100, clock, 5.0);
  LiveCamera camera(reader, 100, clock.clock(), kReadWhenTaken);
  std::size_t handed_over = 0, last = 0;
  double worst_latency_ms = 0.0;
  for (;;) {
    const double came_back_ms = clock.now;
    const std::optional<LiveFrame> frame = camera.grab();
    if (!frame) break;
    if (handed_over > 0) {
      EXPECT_GT(frame->index, last);
    }
    // The newest frame due when the client came back (the one after it was not due yet), or,
    // with nothing new due, the next one.
    if (frame->index + 1 < 100) {
      EXPECT_GT(camera.schedule().dueMs(frame->index + 1), came_back_ms);
    }
    if (frame->skipped > 0) {
      EXPECT_LE(frame->due_ms, came_back_ms);
    }
    EXPECT_EQ(frame->index, handed_over == 0 ? 0 : last + 1 + frame->skipped);
    clock.advance(80.0);  // tracking takes 2.4 frame periods
    worst_latency_ms = std::max(worst_latency_ms, clock.now - frame->due_ms);
    last = frame->index;
    ++handed_over;
  }
  // Every frame is either handed over or skipped, and only handed-over frames were read.
  EXPECT_EQ(handed_over + camera.skipped(), 100u);
  EXPECT_EQ(reader.reads.size(), handed_over);
  EXPECT_EQ(camera.reads(), handed_over);
  EXPECT_GT(camera.skipped(), 50u);
  // Bounded: at most one frame period behind when it is taken, plus the read and the tracking.
  EXPECT_LE(worst_latency_ms, kPeriodMs + 5.0 + 80.0 + 1e-9);
}

TEST(LiveCamera, ASlowReaderKeepsTheLatencyBounded) {
  FakeClock clock;
  ClockedReader reader(200, clock, 60.0);  // reading alone takes 1.8 frame periods
  LiveCamera camera(reader, 200, clock.clock(), kReadWhenTaken);
  double worst_latency_ms = 0.0;
  while (auto frame = camera.grab()) {
    clock.advance(10.0);
    worst_latency_ms = std::max(worst_latency_ms, clock.now - frame->due_ms);
  }
  EXPECT_GT(camera.skipped(), 100u);
  EXPECT_LE(worst_latency_ms, kPeriodMs + 60.0 + 10.0 + 1e-9);
}

// Read ahead on its own thread (reads take no fake time here, so the clock stays the test's): after
// the first late frame, the frame read ahead is the one due when the consumer comes back.
TEST(LiveCamera, ReadingAheadPredictsTheNewestDueFrame) {
  FakeClock clock;
  ClockedReader reader(100, clock, 0.0);
  LiveCamera camera(reader, 100, clock.clock());
  std::size_t handed_over = 0;
  for (;;) {
    const double came_back_ms = clock.now.load();
    const std::optional<LiveFrame> frame = camera.grab();
    if (!frame) break;
    if (frame->index + 1 < 100) {
      EXPECT_GT(camera.schedule().dueMs(frame->index + 1), came_back_ms) << frame->index;
    }
    clock.advance(80.0);
    ++handed_over;
  }
  EXPECT_EQ(handed_over + camera.skipped(), 100u);
  EXPECT_GT(camera.skipped(), 50u);
  // One read in vain, before the consumer's pace was known.
  EXPECT_EQ(camera.unusedReads(), 1u);
  EXPECT_EQ(camera.reads(), handed_over + camera.unusedReads());
  EXPECT_EQ(reader.reads.size(), camera.reads());
}

TEST(LiveCamera, ReadingAheadGivesAFastConsumerEveryFrame) {
  FakeClock clock;
  ClockedReader reader(30, clock, 0.0);
  LiveCamera camera(reader, 30, clock.clock());
  std::size_t expected = 0;
  while (auto frame = camera.grab()) {
    EXPECT_EQ(frame->index, expected++);
    EXPECT_NEAR(clock.now.load(), frame->due_ms, 1e-9);
    clock.advance(10.0);
  }
  EXPECT_EQ(expected, 30u);
  EXPECT_EQ(camera.unusedReads(), 0u);
  EXPECT_EQ(camera.reads(), 30u);
}

TEST(LiveCamera, AReadErrorReachesTheConsumer) {
  class FailingReader : public ClockedReader {
   public:
    using ClockedReader::ClockedReader;
    DatasetFrame load(std::size_t) override { throw DatasetError("frame-000000.png is corrupt"); }
  };
  FakeClock clock;
  FailingReader reader(3, clock, 1.0);
  LiveCamera camera(reader, 3, clock.clock(), kReadWhenTaken);
  EXPECT_THROW(camera.grab(), DatasetError);
  LiveCamera reading_ahead(reader, 3, clock.clock());
  EXPECT_THROW(reading_ahead.grab(), DatasetError);
}

}  // namespace
}  // namespace edgeslam
