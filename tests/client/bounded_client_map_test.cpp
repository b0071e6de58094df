// The client side of a bounded map: applying an eviction drops the keyframe's features and
// observations and the points only evicted keyframes saw, but keeps its pose, which later slices
// still correct; records naming what the client does not hold are ignored; a keyframe sent back
// into the window is whole again.
#include <gtest/gtest.h>

#include "client/slice_applier.h"
#include "map/map_replication.h"
#include "mapping/corridor_map.h"
#include "support/mutex_unlock.h"

namespace edgeslam {
namespace {

class BoundedClientMap : public ::testing::Test {
 protected:
  BoundedClientMap() { edge_.replicateInto(client_); }

  // The client's replica of the edge keyframe k / point i.
  KeyFrame* kf(int k) const REQUIRES(client_.updateMutex()) {
    return client_.keyFrame(edge_.id(k));
  }
  MapPoint* point(int i) const REQUIRES(client_.updateMutex()) {
    return client_.mapPoint(edge_.points[i]->id());
  }

  // As the client's slice thread: applySlice takes the map's mutex itself.
  SliceApplyResult apply(const MapSlice& slice) REQUIRES(client_.updateMutex()) {
    test::MutexUnlock unlock(client_.updateMutex());
    return applySlice(client_, slice, edge_.camera, Sensor::kRgbd);
  }

  MapSlice evicting(std::initializer_list<int> keyframes) {
    MapSlice slice;
    slice.sequence = ++sequence_;
    for (int k : keyframes) slice.keyframes_evicted.push_back(edge_.id(k));
    return slice;
  }

  test::Corridor edge_{10};  // keyframe k sees points 10k .. 10k+39
  Map client_{1};
  std::uint64_t sequence_ = 0;
};

TEST_F(BoundedClientMap, EvictionKeepsThePoseAndDropsWhatOnlyEvictedKeyFramesSaw) {
  MutexLock lock(client_.updateMutex());
  ASSERT_EQ(client_.pointCount(), 130u);
  const SE3d pose_before = kf(2)->pose();
  const SliceApplyResult result = apply(evicting({0, 1, 2, 3, 4}));
  EXPECT_EQ(result.keyframes_evicted.size(), 5u);
  EXPECT_EQ(result.points_evicted, 50u);  // 0..49: keyframe 5 sees 50..89
  EXPECT_EQ(result.keyframes_held, 5u);
  EXPECT_EQ(result.points_held, 80u);
  EXPECT_EQ(client_.keyFrameCount(), 10u);
  EXPECT_EQ(client_.heldKeyFrameCount(), 5u);
  for (int k = 0; k < 5; ++k) {
    ASSERT_NE(kf(k), nullptr) << "keyframe " << k << " must stay as a pose";
    EXPECT_TRUE(kf(k)->isEvicted());
    EXPECT_FALSE(kf(k)->isBad());
    EXPECT_EQ(kf(k)->size(), 0u);
    EXPECT_EQ(kf(k)->features().size(), 0u);
    EXPECT_TRUE(kf(k)->connections().empty());
  }
  EXPECT_TRUE((kf(2)->pose().matrix() - pose_before.matrix()).isZero());
  for (int i = 0; i < 50; ++i) EXPECT_EQ(point(i), nullptr) << "point " << i;
  // Seen by keyframes 4 (evicted) and 5..7: kept, with the held observations only.
  ASSERT_NE(point(75), nullptr);
  EXPECT_EQ(point(75)->observations().size(), 3u);
  EXPECT_FALSE(point(75)->observations().contains(edge_.id(4)));
  // Seen once by a held keyframe (mono weight 1): a replica keeps it (the edge culls points).
  ASSERT_NE(point(55), nullptr);
  EXPECT_EQ(point(55)->observations().size(), 1u);
  EXPECT_TRUE(kf(5)->connections().count(kf(4)) == 0);
  EXPECT_EQ(kf(5)->weight(kf(6)), 30);
  // Evicting again (a repeated slice) changes nothing.
  EXPECT_TRUE(apply(evicting({2})).keyframes_evicted.empty());
}

TEST_F(BoundedClientMap, LaterPoseCorrectionsStillApplyToEvictedKeyFrames) {
  MutexLock lock(client_.updateMutex());
  apply(evicting({0, 1, 2}));
  MapSlice correction;
  correction.sequence = 9;
  const SE3d corrected(Eigen::Quaterniond(Eigen::AngleAxisd(0.1, Eigen::Vector3d::UnitY())),
                       Eigen::Vector3d(0.3, -0.2, 0.05));
  correction.keyframe_poses.push_back({edge_.id(1), corrected, edge_.id(0)});
  EXPECT_EQ(apply(correction).keyframes_moved, 1u);
  EXPECT_TRUE((kf(1)->pose().matrix() - corrected.matrix()).isZero(1e-12));
  EXPECT_TRUE((kf(1)->latestPose().matrix() - corrected.matrix()).isZero(1e-12));
  // Erased on the edge later: it keeps following its parent, as erased keyframes do.
  MapSlice erasure;
  erasure.sequence = 10;
  erasure.keyframes_erased = {edge_.id(1)};
  KeyFrame* erased = kf(1);
  apply(erasure);
  EXPECT_TRUE(erased->isBad());
  EXPECT_EQ(client_.heldKeyFrameCount(), 7u);
  EXPECT_EQ(client_.keyFrameCount(), 9u);
  EXPECT_TRUE((erased->latestPose().matrix() - corrected.matrix()).isZero(1e-9));
}

TEST_F(BoundedClientMap, RecordsForWhatTheClientDoesNotHoldAreIgnored) {
  MutexLock lock(client_.updateMutex());
  apply(evicting({0, 1, 2, 3, 4}));
  const std::size_t points = client_.pointCount();
  MapSlice slice;
  slice.sequence = 7;
  slice.newest_keyframe = edge_.id(9);
  // Point 20 is seen by keyframes 0..2 only: evicted on the client, not created again.
  slice.points_upserted.push_back(mapPointRecord(*edge_.points[20]));
  slice.point_positions.push_back({edge_.points[30]->id(), {9, 9, 9}});
  slice.points_erased.push_back(edge_.points[10]->id());
  slice.keyframe_poses.push_back({0x0100000000abcdefULL, SE3d(), kInvalidId});
  slice.keyframes_evicted.push_back(0x0100000000abcdefULL);
  // Point 48 is seen by keyframes 1..4, all evicted: not created either. Point 55 (keyframes 2..5)
  // moved on the edge: applied, with the observation in keyframe 5 only.
  slice.points_upserted.push_back(mapPointRecord(*edge_.points[48]));
  MapPointRecord moved = mapPointRecord(*edge_.points[55]);
  moved.position = {1, 2, 3};
  slice.points_upserted.push_back(moved);
  const SliceApplyResult result = apply(slice);
  EXPECT_EQ(result.points_upserted, 1u);
  EXPECT_EQ(result.points_moved, 0u);
  EXPECT_EQ(result.points_erased, 0u);
  EXPECT_EQ(result.keyframes_moved, 0u);
  EXPECT_TRUE(result.keyframes_evicted.empty());
  EXPECT_EQ(client_.pointCount(), points);
  EXPECT_EQ(point(20), nullptr);
  EXPECT_EQ(point(48), nullptr);
  ASSERT_NE(point(55), nullptr);
  EXPECT_TRUE(point(55)->position().isApprox(Eigen::Vector3d(1, 2, 3)));
  EXPECT_EQ(point(55)->observations().size(), 1u);
}

TEST_F(BoundedClientMap, KeyFrameBackInTheWindowIsWholeAgain) {
  MutexLock lock(client_.updateMutex());
  apply(evicting({0, 1, 2, 3, 4}));
  // What the edge sends on a revisit: keyframe 4 and the points of it the client lacks.
  MapSlice slice;
  slice.sequence = 5;
  slice.newest_keyframe = edge_.id(9);
  slice.keyframes.push_back(keyFrameRecord(*edge_.keyframes[4]));
  for (int i = 40; i < 50; ++i) slice.points_upserted.push_back(mapPointRecord(*edge_.points[i]));
  const SliceApplyResult result = apply(slice);
  ASSERT_EQ(result.keyframes_entered.size(), 1u);
  EXPECT_EQ(result.keyframes_entered[0], edge_.id(4));
  EXPECT_FALSE(kf(4)->isEvicted());
  EXPECT_EQ(client_.heldKeyFrameCount(), 6u);
  ASSERT_EQ(kf(4)->size(), static_cast<std::size_t>(test::Corridor::kSpan));
  for (int i = 0; i < test::Corridor::kSpan; ++i) {
    const MapPoint* p = kf(4)->point(static_cast<std::size_t>(i));
    ASSERT_NE(p, nullptr) << "keypoint " << i;
    EXPECT_EQ(p->id(), edge_.points[40 + i]->id());
  }
  EXPECT_EQ(point(75)->observations().size(), 4u);  // 4..7 again
  EXPECT_EQ(kf(4)->weight(kf(5)), 30);
  EXPECT_EQ(kf(5)->weight(kf(4)), 30);
  EXPECT_EQ(point(45)->observations().size(), 1u);  // 1..4 see it on the edge; 4 is held
}

}  // namespace
}  // namespace edgeslam
