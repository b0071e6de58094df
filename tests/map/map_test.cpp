// The map as the single place of change: links, covisibility, spanning tree and the change record.
#include "map/map.h"

#include <gtest/gtest.h>

#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

struct TwoKeyFrames {
  test::SyntheticScene scene{300, 7};
  Map map;
  KeyFrame* kf0 = nullptr;
  KeyFrame* kf1 = nullptr;
  std::vector<MapPoint*> shared;

  TwoKeyFrames() {
    const auto v0 = scene.view(test::poseAt({0, 0, 0}), 0, false);
    const auto v1 = scene.view(test::poseAt({0.2, 0, 0}), 0, false);
    kf0 = scene.addKeyFrame(map, v0, 0, true);
    kf1 = scene.addKeyFrame(map, v1, 1, false);
    // Link kf1's keypoints to kf0's points of the same scene point.
    for (std::size_t i = 0; i < v1.scene_point.size(); ++i) {
      for (std::size_t j = 0; j < v0.scene_point.size(); ++j) {
        if (v0.scene_point[j] == v1.scene_point[i] && kf0->point(j) != nullptr) {
          map.addObservation(kf0->point(j), kf1, i);
          shared.push_back(kf0->point(j));
        }
      }
    }
    map.updateConnections(kf0);
    map.updateConnections(kf1);
  }
};

TEST(Map, RecordsCreationsAndForgetsPointsBornAndDeadInOneSlice) {
  TwoKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  MapChanges first = t.map.takeChanges();
  EXPECT_EQ(first.keyframes_created.size(), 2u);
  EXPECT_EQ(first.points_created.size(), t.map.pointCount());
  EXPECT_TRUE(t.map.changes().empty());

  MapPoint* fresh = t.map.createMapPoint({0, 0, 3}, t.kf0);
  t.map.erasePoint(fresh);
  MapPoint* old = t.shared.front();
  t.map.setPointPosition(old, old->position() + Eigen::Vector3d(0.01, 0, 0));
  const MapChanges second = t.map.takeChanges();
  EXPECT_FALSE(second.points_created.contains(fresh->id()));
  EXPECT_FALSE(second.points_erased.contains(fresh->id()));
  EXPECT_TRUE(second.points_moved.contains(old->id()));
  EXPECT_FALSE(second.points_updated.contains(old->id()));

  t.map.erasePoint(old);
  const MapChanges third = t.map.takeChanges();
  EXPECT_TRUE(third.points_erased.contains(old->id()));
  EXPECT_EQ(t.map.mapPoint(old->id()), nullptr);
}

TEST(Map, ObservationsLinkBothWaysAndCovisibilityIsSymmetric) {
  TwoKeyFrames t;
  ASSERT_GT(t.shared.size(), 50u);
  MapPoint* p = t.shared.front();
  EXPECT_EQ(p->observations().size(), 2u);
  EXPECT_EQ(t.kf0->weight(t.kf1), static_cast<int>(t.shared.size()));
  EXPECT_EQ(t.kf1->weight(t.kf0), static_cast<int>(t.shared.size()));
  EXPECT_EQ(t.kf1->parent(), t.kf0);
  EXPECT_TRUE(t.kf0->children().contains(t.kf1));
  EXPECT_EQ(t.kf0->bestCovisibles(5), std::vector<KeyFrame*>{t.kf1});
}

TEST(Map, AMonocularPointWithOneObservationLeftIsErased) {
  TwoKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  MapPoint* p = t.shared.front();
  const MapPointId id = p->id();
  t.map.eraseObservation(p, t.kf1);
  EXPECT_TRUE(p->isBad());
  EXPECT_EQ(t.map.mapPoint(id), nullptr);
  for (MapPoint* q : t.kf0->points()) EXPECT_NE(q, p);
}

TEST(Map, ReplacePointMovesObservations) {
  TwoKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  MapPoint* other = t.shared[1];
  const int scene_point = t.scene.sceneOf(other);
  // A third keyframe sees the same scene point and made its own (duplicate) point for it.
  const auto v2 = t.scene.view(test::poseAt({0.4, 0, 0}), 0, false);
  KeyFrame* kf2 = t.scene.addKeyFrame(t.map, v2, 2, false);
  std::size_t index = v2.scene_point.size();
  for (std::size_t i = 0; i < v2.scene_point.size(); ++i) {
    if (v2.scene_point[i] == scene_point) index = i;
  }
  ASSERT_LT(index, v2.scene_point.size());
  MapPoint* duplicate = t.map.createMapPoint(other->position(), kf2);
  t.map.addObservation(duplicate, kf2, index);
  t.map.replacePoint(duplicate, other);
  EXPECT_TRUE(duplicate->isBad());
  EXPECT_EQ(duplicate->replacedBy(), other);
  EXPECT_EQ(kf2->point(index), other);
  EXPECT_EQ(other->observations().size(), 3u);
}

TEST(Map, ErasedKeyFrameFollowsItsParentsLaterCorrection) {
  TwoKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  t.map.takeChanges();  // the keyframe reached the other side before it is erased
  KeyFrame* kf1 = t.kf1;
  const SE3d before = kf1->pose();
  t.map.eraseKeyFrame(kf1);
  EXPECT_TRUE(kf1->isBad());
  EXPECT_EQ(t.map.keyFrame(kf1->id()), nullptr);
  EXPECT_FALSE(t.kf0->children().contains(kf1));
  EXPECT_LT((kf1->latestPose().log() - before.log()).norm(), 1e-12);
  // Moving the parent moves the erased keyframe's latest pose rigidly with it.
  Vector6d shift;
  shift << 0.1, 0, 0, 0, 0.05, 0;
  const SE3d moved = t.kf0->pose() * SE3d::exp(shift);
  t.map.setKeyFramePose(t.kf0, moved);
  // kf0 was at the identity, so kf1's pose relative to it was `before`.
  EXPECT_LT(((before * moved).log() - kf1->latestPose().log()).norm(), 1e-9);
  EXPECT_TRUE(t.map.changes().keyframes_erased.contains(kf1->id()));
}

TEST(Map, AKeyFrameCulledAsARevisitHangsFromTheKeyFrameThatSawTheSame) {
  // kf0 <- kf1 <- kf2 (kf2 the newest, just mapped), and kf3 elsewhere in the tree (another
  // client's, merged) at kf2's place. Culled for kf3, kf2 and whoever hangs from it follow kf3:
  // on a merged map its old parent may be far behind the camera.
  TwoKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  const auto v2 = t.scene.view(test::poseAt({0.4, 0, 0}), 0, false);
  KeyFrame* kf2 = t.scene.addKeyFrame(t.map, v2, 2, true);
  KeyFrame* kf3 = t.scene.addKeyFrame(t.map, v2, 3, true);
  t.map.hangTreeFrom(kf2, t.kf1);
  t.map.hangTreeFrom(kf3, t.kf0);
  const auto v4 = t.scene.view(test::poseAt({0.5, 0, 0}), 0, false);
  KeyFrame* kf4 = t.scene.addKeyFrame(t.map, v4, 4, true);
  t.map.hangTreeFrom(kf4, kf2);
  ASSERT_EQ(kf2->parent(), t.kf1);
  EXPECT_TRUE(t.map.hangsFrom(kf4, t.kf0));
  EXPECT_FALSE(t.map.hangsFrom(kf3, kf2));

  t.map.eraseKeyFrame(kf2, kf3);
  EXPECT_TRUE(kf2->isBad());
  EXPECT_EQ(kf2->parent(), kf3);
  EXPECT_EQ(kf4->parent(), kf3);
  EXPECT_TRUE(kf3->children().contains(kf4));
  EXPECT_FALSE(t.kf1->children().contains(kf2));
  // Its latest pose follows kf3 now.
  const SE3d kf3_before = kf3->pose();
  Vector6d shift;
  shift << 0.1, 0, 0, 0, 0, 0;
  t.map.setKeyFramePose(kf3, kf3_before * SE3d::exp(shift));
  EXPECT_LT((kf2->latestPose().log() - kf3->pose().log()).norm(), 1e-9);

  // A keyframe is never hung from its own descendant (no cycle): it stays with its parent.
  KeyFrame* kf5 = t.scene.addKeyFrame(t.map, v4, 5, true);
  t.map.hangTreeFrom(kf5, kf4);
  t.map.eraseKeyFrame(kf4, kf5);
  EXPECT_EQ(kf4->parent(), kf3);
  EXPECT_EQ(kf5->parent(), kf3);
}

TEST(Map, TheOriginKeyFrameIsNeverErased) {
  TwoKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  t.map.eraseKeyFrame(t.kf0);
  EXPECT_FALSE(t.kf0->isBad());
}

TEST(Map, ClearEmptiesButIdsKeepGrowing) {
  TwoKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  const KeyFrameId last = t.kf1->id();
  t.map.clear();
  EXPECT_EQ(t.map.keyFrameCount(), 0u);
  EXPECT_EQ(t.map.pointCount(), 0u);
  EXPECT_EQ(t.map.originKeyFrame(), nullptr);
  const auto v = t.scene.view(test::poseAt({0, 0, 0}), 0, false);
  KeyFrame* again = t.map.createKeyFrame(5, 0.0, v.features, SE3d());
  EXPECT_GT(again->id(), last);
  EXPECT_EQ(t.map.originKeyFrame(), again);
}

TEST(IdAllocator, OriginsNeverCollide) {
  IdAllocator edge(0), client(1);
  const auto a = edge.next();
  const auto b = client.next();
  EXPECT_NE(a, b);
  EXPECT_EQ(idOrigin(a), 0);
  EXPECT_EQ(idOrigin(b), 1);
  client.advancePast(b + 10);
  EXPECT_GT(client.next(), b + 10);
}

}  // namespace
}  // namespace edgeslam
