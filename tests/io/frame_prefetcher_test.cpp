#include "io/frame_prefetcher.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>

namespace edgeslam {
namespace {

CameraIntrinsics smallIntrinsics() {
  CameraIntrinsics k;
  k.width = 8;
  k.height = 8;
  k.fx = k.fy = 10.0;
  k.cx = k.cy = 4.0;
  return k;
}

PinholeCamera smallCamera() {
  return PinholeCamera(smallIntrinsics());
}

// Frames whose grey image holds their index; loading frame `fail_at` throws, and every load
// takes `load_delay`.
class CountingReader : public DatasetReader {
 public:
  CountingReader(std::size_t count, std::size_t fail_at, std::chrono::milliseconds load_delay)
      : camera_(smallCamera()),
        stamps_(count),
        truth_(count),
        fail_at_(fail_at),
        load_delay_(load_delay) {
    info_.frame_count = count;
    for (std::size_t i = 0; i < count; ++i) stamps_[i] = 0.1 * static_cast<double>(i);
  }
  const DatasetInfo& info() const override { return info_; }
  const PinholeCamera& camera() const override { return camera_; }
  const std::vector<double>& timestamps() const override { return stamps_; }
  const std::vector<std::optional<SE3d>>& groundTruth() const override { return truth_; }
  DatasetFrame load(std::size_t index) override {
    ++loads;
    std::this_thread::sleep_for(load_delay_);
    if (index == fail_at_) throw DatasetError("frame " + std::to_string(index) + " is corrupt");
    ++loaded;
    DatasetFrame frame;
    frame.index = index;
    frame.timestamp = stamps_[index];
    frame.gray = cv::Mat(8, 8, CV_8UC1, cv::Scalar(static_cast<double>(index)));
    return frame;
  }

  std::atomic<std::size_t> loads{0};   // loads started
  std::atomic<std::size_t> loaded{0};  // loads finished

 private:
  DatasetInfo info_;
  PinholeCamera camera_;
  std::vector<double> stamps_;
  std::vector<std::optional<SE3d>> truth_;
  std::size_t fail_at_;
  std::chrono::milliseconds load_delay_;
};

constexpr std::size_t kNever = 1000;

// Waits (up to 10 s) until the reader has loaded `count` frames, then a little longer so that a
// prefetcher reading too far would be seen doing it.
void waitForLoads(const CountingReader& reader, std::size_t count) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (reader.loads.load() < count && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
}

TEST(FramePrefetcher, HandsOverEveryFrameInOrder) {
  CountingReader reader(20, kNever, std::chrono::milliseconds(0));
  FramePrefetcher prefetcher(reader, 20, {.frames_ahead = 3});
  for (std::size_t i = 0; i < 20; ++i) {
    const PrefetchedFrame f = prefetcher.next();
    EXPECT_EQ(f.frame.index, i);
    EXPECT_EQ(f.frame.gray.at<std::uint8_t>(0, 0), i);
    EXPECT_GE(f.load_ms, 0.0);
  }
  EXPECT_THROW(prefetcher.next(), std::out_of_range);
}

TEST(FramePrefetcher, ReadsNoFurtherAheadThanAsked) {
  CountingReader reader(50, kNever, std::chrono::milliseconds(0));
  FramePrefetcher prefetcher(reader, 50, {.frames_ahead = 4});
  prefetcher.next();
  waitForLoads(reader, 5);
  // One handed out, four waiting: the fifth ahead is not read until one more is taken.
  EXPECT_EQ(reader.loads.load(), 5u);
  prefetcher.next();
  waitForLoads(reader, 6);
  EXPECT_EQ(reader.loads.load(), 6u);
}

TEST(FramePrefetcher, TellsWhetherTheNextFrameIsReadAlready) {
  CountingReader reader(2, kNever, std::chrono::milliseconds(0));
  FramePrefetcher prefetcher(reader, 2, {.frames_ahead = 2});
  prefetcher.next();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (!prefetcher.nextIsReady() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  EXPECT_TRUE(prefetcher.nextIsReady());
  prefetcher.next();
  EXPECT_FALSE(prefetcher.nextIsReady());  // nothing after the last frame
}

TEST(FramePrefetcher, ReadsWhileTheConsumerWorks) {
  // 100 ms per read: while the consumer works on frame 0, frames 1-4 are read, and taking them
  // then costs no read at all.
  CountingReader reader(10, kNever, std::chrono::milliseconds(100));
  FramePrefetcher prefetcher(reader, 10, {.frames_ahead = 4});
  prefetcher.next();
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(10);
  while (reader.loaded.load() < 5 && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_EQ(reader.loaded.load(), 5u);
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 4; ++i) prefetcher.next();
  const double waited_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LT(waited_ms, 100.0);
}

TEST(FramePrefetcher, AReadErrorReachesTheConsumerAtThatFrame) {
  CountingReader reader(10, 3, std::chrono::milliseconds(0));
  FramePrefetcher prefetcher(reader, 10, {.frames_ahead = 2});
  for (std::size_t i = 0; i < 3; ++i) EXPECT_EQ(prefetcher.next().frame.index, i);
  try {
    prefetcher.next();
    FAIL() << "frame 3 should have thrown";
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("frame 3 is corrupt"), std::string::npos);
  }
}

TEST(FramePrefetcher, StopsEarlyWithoutReadingTheRest) {
  CountingReader reader(1000, kNever, std::chrono::milliseconds(1));
  {
    FramePrefetcher prefetcher(reader, 1000, {.frames_ahead = 2});
    prefetcher.next();
  }
  EXPECT_LT(reader.loads.load(), 10u);
}

TEST(FramePrefetcher, RejectsZeroFramesAhead) {
  CountingReader reader(1, kNever, std::chrono::milliseconds(0));
  EXPECT_THROW(FramePrefetcher(reader, 1, {.frames_ahead = 0}), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
