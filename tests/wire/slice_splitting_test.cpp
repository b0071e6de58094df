#include "wire/slice_splitting.h"

#include <gtest/gtest.h>

#include <chrono>
#include <random>

#include "wire/net_test_records.h"
#include "wire/slice_queue.h"
#include "wire/wire_convert.h"

namespace edgeslam {
namespace {

using namespace std::chrono_literals;

// A full resync of a map too big for one message: 3 keyframes, 400 points.
MapSlice bigResync(std::mt19937& rng) {
  MapSlice s;
  s.full_resync = true;
  s.newest_keyframe = test::clientId(3, 9);
  for (int i = 0; i < 3; ++i) {
    s.keyframes.push_back(test::sampleKeyFrame(test::clientId(3, 1 + i), 200, rng, false));
    s.keyframe_poses.push_back({test::clientId(3, 1 + i), test::samplePose(rng), kInvalidId});
  }
  for (int i = 0; i < 400; ++i) {
    s.points_upserted.push_back(test::samplePoint(test::clientId(0, 100 + i), rng));
  }
  s.map_keyframes = 3;
  s.map_points = 400;
  return s;
}

TEST(SliceSplitting, PartsFitAndKeepEveryRecordWithTheHeaderLast) {
  std::mt19937 rng(3);
  const MapSlice whole = bigResync(rng);
  const std::size_t limit = wireSize(whole) / 5;
  const auto parts = splitSlice(whole, limit, [](const MapSlice& s) { return wireSize(s); });
  ASSERT_GE(parts.size(), 5u);
  std::size_t keyframes = 0, points = 0;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    EXPECT_LE(wireSize(parts[i]), limit) << "part " << i;
    EXPECT_EQ(parts[i].full_resync, i + 1 == parts.size()) << "part " << i;
    EXPECT_EQ(parts[i].newest_keyframe, whole.newest_keyframe);
    // Keyframe records come before the points that may observe them.
    if (!parts[i].points_upserted.empty()) {
      EXPECT_EQ(keyframes, whole.keyframes.size());
    }
    keyframes += parts[i].keyframes.size();
    points += parts[i].points_upserted.size();
  }
  EXPECT_EQ(keyframes, whole.keyframes.size());
  EXPECT_EQ(points, whole.points_upserted.size());
  EXPECT_EQ(parts.back().keyframe_poses.size(), whole.keyframe_poses.size());
  EXPECT_EQ(parts.back().map_points, 400u);
}

TEST(SliceSplitting, ARecordLargerThanAMessageIsRefusedNotDropped) {
  std::mt19937 rng(4);
  MapSlice s;
  s.keyframes.push_back(test::sampleKeyFrame(test::clientId(3, 1), 500, rng, false));
  EXPECT_THROW(splitSlice(s, 1000, [](const MapSlice& x) { return wireSize(x); }), SliceTooLarge);
}

TEST(SliceSplitting, PushSplitsWhatTheQueueWouldRefuse) {
  std::mt19937 rng(5);
  const MapSlice whole = bigResync(rng);
  SliceQueueLimits limits;
  limits.max_message_bytes = wireSize(whole) / 3;
  SliceQueue queue(limits);
  EXPECT_THROW(queue.push(whole), WireError);
  const SlicePushResult pushed = pushSplitting(queue, whole);
  EXPECT_GE(pushed.parts, 3u);
  std::size_t points = 0;
  for (std::uint64_t sequence = 1; sequence <= pushed.parts; ++sequence) {
    const auto got = queue.waitFrom(sequence, 10ms);
    ASSERT_EQ(got.status, SliceQueue::WaitStatus::kSlice);
    points += got.slice->points_upserted().count();
    EXPECT_EQ(got.slice->full_resync(), sequence == pushed.parts);
  }
  EXPECT_EQ(points, whole.points_upserted.size());
  // A small slice goes as it is.
  EXPECT_EQ(pushSplitting(queue, MapSlice{}).parts, 1u);
}

}  // namespace
}  // namespace edgeslam
