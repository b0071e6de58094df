// The client's map records its own changes (tracking makes keyframes and points with recording on)
// but nobody reads that record: a slice drops it. Before, the points the client made and the edge
// then culled stayed in the record for good (their erasure comes with a slice, unrecorded): a map
// that culled as much as it made still grew, ~7000 ids a pass of redkitchen 0-299.
#include <gtest/gtest.h>

#include <algorithm>

#include "client/slice_applier.h"
#include "map/synthetic_views.h"
#include "support/mutex_unlock.h"

namespace edgeslam {
namespace {

std::size_t recordedChanges(const Map& map) REQUIRES(map.updateMutex()) {
  const MapChanges& c = map.changes();
  return c.points_created.size() + c.points_updated.size() + c.points_moved.size() +
         c.points_erased.size() + c.keyframes_created.size() + c.keyframes_updated.size() +
         c.keyframes_erased.size();
}

TEST(ClientChangeRecord, StaysBoundedWhileTheEdgeCullsWhatTheClientMakes) {
  test::SyntheticScene scene{200, 5};
  Map client{1};
  MutexLock lock(client.updateMutex());
  // The map's origin, which stays.
  scene.addKeyFrame(client, scene.view(test::poseAt({0, 0, 0}), 0, true), 0, true);
  std::size_t made_per_round = 0;
  for (int round = 1; round <= 30; ++round) {
    // As tracking does: a keyframe with its own points, recorded.
    KeyFrame* kf =
        scene.addKeyFrame(client, scene.view(test::poseAt({0.01 * (round % 3), 0, 0}), 0, true),
                          static_cast<std::size_t>(10 * round), true);
    ASSERT_GT(kf->size(), 50u);
    made_per_round = std::max(made_per_round, recordedChanges(client));
    // The edge culled it as a revisit, and its points with it.
    MapSlice slice;
    slice.sequence = static_cast<std::uint64_t>(round);
    slice.processed_keyframe = kf->id();
    slice.keyframes_erased.push_back(kf->id());
    for (MapPoint* p : kf->goodPoints()) slice.points_erased.push_back(p->id());
    SliceApplyResult applied;
    {
      test::MutexUnlock unlock(client.updateMutex());  // applySlice takes it
      applied = applySlice(client, slice, scene.camera(), Sensor::kRgbd);
    }
    ASSERT_EQ(applied.keyframes_erased, 1u);
    ASSERT_EQ(applied.points_erased, slice.points_erased.size());
    EXPECT_EQ(recordedChanges(client), 0u) << "round " << round;
  }
  // What one keyframe made, not thirty (before: 30 x its points and keyframe).
  EXPECT_LE(recordedChanges(client), made_per_round);
  EXPECT_GT(made_per_round, 50u);
  EXPECT_EQ(client.heldKeyFrameCount(), 1u);
}

}  // namespace
}  // namespace edgeslam
