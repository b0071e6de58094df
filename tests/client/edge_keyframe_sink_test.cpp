#include "client/edge_keyframe_sink.h"

#include <gtest/gtest.h>

#include <vector>

#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

class RecordingUplink final : public KeyFrameUplink {
 public:
  void send(KeyFrameUpload upload) override { sent.push_back(upload.sequence); }
  bool reconnecting() const override { return edge_unreachable; }
  std::vector<std::uint64_t> sent;
  bool edge_unreachable = false;
};

TEST(EdgeKeyFrameSink, StarvingTrackingMayHaveAFewMoreUploadsInFlight) {
  Map map;
  RecordingUplink uplink;
  EdgeKeyFrameSinkOptions options;
  options.max_in_flight = 3;
  options.urgent_extra_in_flight = 2;
  EdgeKeyFrameSink sink(map, uplink, options);
  const auto features = test::emptyFeatures(test::syntheticCamera());
  const auto upload = [&](std::size_t frame) {
    KeyFrame* keyframe = nullptr;
    {
      MutexLock lock(map.updateMutex());
      keyframe = map.createKeyFrame(frame, 0.0, features, SE3d());
    }
    sink.insertKeyFrame(keyframe);  // takes the map's mutex itself
  };
  for (std::size_t frame = 0; frame < 3; ++frame) {
    EXPECT_TRUE(sink.acceptsKeyFrames());
    upload(frame);
  }
  EXPECT_FALSE(sink.acceptsKeyFrames());  // 3 unanswered
  EXPECT_TRUE(sink.acceptsUrgentKeyFrames());
  upload(3);
  upload(4);
  EXPECT_FALSE(sink.acceptsUrgentKeyFrames());  // 5 unanswered: the urgent bound too
  sink.onSliceApplied(2, 1);                    // the edge answered the first two: 3 left
  EXPECT_TRUE(sink.acceptsUrgentKeyFrames());
  EXPECT_FALSE(sink.acceptsKeyFrames());
  sink.onSliceApplied(5, 4);
  EXPECT_TRUE(sink.acceptsKeyFrames());
  EXPECT_EQ(uplink.sent.size(), 5u);
}

// While the edge is unreachable tracking may leave more keyframes unanswered, and no map update
// can come: an overdue one then forces no keyframe (keyframe_policy.h).
TEST(EdgeKeyFrameSink, MapUpdatesArePausedWhileTheEdgeIsUnreachable) {
  Map map;
  RecordingUplink uplink;
  EdgeKeyFrameSinkOptions options;
  options.max_in_flight = 1;
  options.urgent_extra_in_flight = 0;
  options.max_in_flight_reconnecting = 2;
  EdgeKeyFrameSink sink(map, uplink, options);
  const auto features = test::emptyFeatures(test::syntheticCamera());
  EXPECT_FALSE(sink.mapUpdatesPaused());
  KeyFrame* keyframe = nullptr;
  {
    MutexLock lock(map.updateMutex());
    keyframe = map.createKeyFrame(0, 0.0, features, SE3d());
  }
  sink.insertKeyFrame(keyframe);
  EXPECT_FALSE(sink.acceptsKeyFrames());
  uplink.edge_unreachable = true;
  EXPECT_TRUE(sink.mapUpdatesPaused());
  EXPECT_TRUE(sink.acceptsKeyFrames());
  uplink.edge_unreachable = false;
  EXPECT_FALSE(sink.mapUpdatesPaused());
}

// A server restart (issue 19): the keyframes made while the edge was down are answered one by
// one once it is back, a second or more each on a loaded host. Counted against max_in_flight they
// refused tracking every keyframe meanwhile, and tracking was lost at the next turn; the bounds
// apply to the uploads after that backlog, and the reconnecting bound to all of them.
TEST(EdgeKeyFrameSink, AnOutagesBacklogDoesNotHoldBackTrackingOnceTheEdgeIsBack) {
  Map map;
  RecordingUplink uplink;
  EdgeKeyFrameSinkOptions options;
  options.max_in_flight = 3;
  options.urgent_extra_in_flight = 1;
  options.max_in_flight_reconnecting = 9;
  EdgeKeyFrameSink sink(map, uplink, options);
  const auto features = test::emptyFeatures(test::syntheticCamera());
  std::vector<KeyFrame*> keyframes;
  const auto upload = [&](std::size_t frame) {
    {
      MutexLock lock(map.updateMutex());
      keyframes.push_back(map.createKeyFrame(frame, 0.0, features, SE3d()));
    }
    sink.insertKeyFrame(keyframes.back());
  };
  upload(0);
  uplink.edge_unreachable = true;
  for (std::size_t frame = 1; frame < 6; ++frame) {
    EXPECT_TRUE(sink.acceptsKeyFrames());
    upload(frame);
  }
  uplink.edge_unreachable = false;  // back: 6 unanswered, all of the outage's backlog
  EXPECT_EQ(sink.uploadsInFlight(), 6u);
  EXPECT_EQ(sink.uploadsInFlightAfterBacklog(), 0u);
  EXPECT_TRUE(sink.acceptsKeyFrames());
  upload(6);
  upload(7);
  EXPECT_TRUE(sink.acceptsKeyFrames());  // 2 after the backlog
  upload(8);
  EXPECT_FALSE(sink.acceptsKeyFrames());        // 3 after it: max_in_flight
  EXPECT_FALSE(sink.acceptsUrgentKeyFrames());  // 9 in all: the reconnecting bound
  sink.onSliceApplied(2, 1);                    // 7 in all
  EXPECT_TRUE(sink.acceptsUrgentKeyFrames());
  EXPECT_FALSE(sink.acceptsKeyFrames());
  sink.onSliceApplied(7, 6);  // the backlog answered, and the first upload after it
  EXPECT_EQ(sink.uploadsInFlightAfterBacklog(), 2u);
  EXPECT_TRUE(sink.acceptsKeyFrames());
  // A keyframe sent again after a full resync is backlog too.
  EXPECT_TRUE(sink.resendKeyFrame(keyframes[3]->id()));
  EXPECT_EQ(sink.uploadsInFlightAfterBacklog(), 0u);
  EXPECT_EQ(sink.uploadsInFlight(), 3u);
}

}  // namespace
}  // namespace edgeslam
