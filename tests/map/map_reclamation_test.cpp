// Erased map elements are freed once every thread that keeps pointers beyond the map's mutex (a
// MapParticipant) has passed a quiescent point after the erasure, and not before.
#include <gtest/gtest.h>

#include <mutex>

#include "map/map.h"
#include "map/map_participant.h"
#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

struct ThreeKeyFrames {
  test::SyntheticScene scene{300, 11};
  Map map;
  KeyFrame* kf0 = nullptr;
  KeyFrame* kf1 = nullptr;
  KeyFrame* kf2 = nullptr;

  // kf1 and kf2 observe kf0's points, so kf0 is their parent in the spanning tree.
  ThreeKeyFrames() {
    const auto v0 = scene.view(test::poseAt({0, 0, 0}), 0, false);
    kf0 = scene.addKeyFrame(map, v0, 0, true);
    KeyFrame** others[] = {&kf1, &kf2};
    for (std::size_t k = 0; k < 2; ++k) {
      const auto v = scene.view(test::poseAt({0.1 * static_cast<double>(k + 1), 0, 0}), 0, false);
      KeyFrame* kf = scene.addKeyFrame(map, v, k + 1, false);
      for (std::size_t i = 0; i < v.scene_point.size(); ++i) {
        for (std::size_t j = 0; j < v0.scene_point.size(); ++j) {
          if (v0.scene_point[j] == v.scene_point[i] && kf0->point(j) != nullptr) {
            map.addObservation(kf0->point(j), kf, i);
          }
        }
      }
      *others[k] = kf;
    }
    for (KeyFrame* kf : {kf0, kf1, kf2}) map.updateConnections(kf);
  }
};

TEST(MapReclamation, AnErasedPointWaitsForEveryParticipantsQuiescentPoint) {
  ThreeKeyFrames t;
  MapParticipant tracking(t.map, "tracking");
  MapParticipant mapping(t.map, "mapping");
  MutexLock lock(t.map.updateMutex());
  const std::size_t points = t.map.pointCount();
  ASSERT_GT(points, 10u);
  MapPoint* erased = t.kf1->goodPoints().front();
  t.map.erasePoint(erased);
  EXPECT_EQ(t.map.reclamation().points_waiting, 1u);

  tracking.quiescent(t.map);
  // The mapping participant may still hold it: still allocated, still marked bad.
  EXPECT_TRUE(erased->isBad());
  EXPECT_EQ(t.map.reclamation().points_waiting, 1u);
  EXPECT_EQ(t.map.reclamation().points_freed, 0u);

  mapping.quiescent(t.map);
  EXPECT_EQ(t.map.reclamation().points_waiting, 0u);
  EXPECT_EQ(t.map.reclamation().points_freed, 1u);
  EXPECT_EQ(t.map.pointCount(), points - 1);
}

TEST(MapReclamation, ErasuresAfterAQuiescentPointWaitForTheNextOne) {
  ThreeKeyFrames t;
  MapParticipant mapping(t.map, "mapping");
  MutexLock lock(t.map.updateMutex());
  t.map.erasePoint(t.kf0->goodPoints().front());
  mapping.quiescent(t.map);
  t.map.erasePoint(t.kf0->goodPoints().front());
  EXPECT_EQ(t.map.reclamation().points_freed, 1u);
  EXPECT_EQ(t.map.reclamation().points_waiting, 1u);
  mapping.quiescent(t.map);
  EXPECT_EQ(t.map.reclamation().points_freed, 2u);
}

TEST(MapReclamation, ParticipantThatLeavesNoLongerHoldsAnythingBack) {
  ThreeKeyFrames t;
  MapParticipant tracking(t.map, "tracking");
  {
    MapParticipant global_ba(t.map, "global BA");
    MutexLock lock(t.map.updateMutex());
    t.map.erasePoint(t.kf2->goodPoints().front());
    tracking.quiescent(t.map);
    EXPECT_EQ(t.map.reclamation().points_freed, 0u);
    EXPECT_EQ(t.map.reclamation().participants, 2u);
  }
  MutexLock lock(t.map.updateMutex());
  EXPECT_EQ(t.map.reclamation().points_freed, 1u);
  EXPECT_EQ(t.map.reclamation().participants, 1u);
}

TEST(MapReclamation, WithoutParticipantsErasedElementsStayUntilTheMapGoes) {
  ThreeKeyFrames t;
  MutexLock lock(t.map.updateMutex());
  t.map.erasePoint(t.kf0->goodPoints().front());
  t.map.eraseKeyFrame(t.kf1);
  EXPECT_EQ(t.map.reclamation().points_freed, 0u);
  EXPECT_EQ(t.map.reclamation().keyframes_waiting, 1u);
  EXPECT_GT(t.kf1->features().size(), 0u);
}

TEST(MapReclamation, AnErasedKeyFrameDropsItsFeaturesButKeepsItsPoseInTheTree) {
  ThreeKeyFrames t;
  MapParticipant tracking(t.map, "tracking");
  MutexLock lock(t.map.updateMutex());
  const SE3d pose_before = t.kf1->pose();
  const int scale_levels = t.kf1->features().scales.numLevels();
  t.map.eraseKeyFrame(t.kf1);
  ASSERT_TRUE(t.kf1->isBad());
  tracking.quiescent(t.map);
  EXPECT_EQ(t.map.reclamation().keyframes_released, 1u);
  EXPECT_EQ(t.kf1->features().size(), 0u);
  EXPECT_TRUE(t.kf1->points().empty());
  EXPECT_EQ(t.kf1->place(), nullptr);
  // What projections and the trajectory need stays: scales, and the pose through the tree.
  EXPECT_EQ(t.kf1->features().scales.numLevels(), scale_levels);
  EXPECT_LT((t.kf1->latestPose().translation() - pose_before.translation()).norm(), 1e-12);
  // Moving its old parent moves it along.
  ASSERT_NE(t.kf1->parent(), nullptr);
  KeyFrame* parent = t.kf1->parent();
  const SE3d shift = SE3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.5, 0, 0));
  t.map.setKeyFramePose(parent, parent->pose() * shift);
  EXPECT_GT((t.kf1->latestPose().translation() - pose_before.translation()).norm(), 0.1);
}

}  // namespace
}  // namespace edgeslam
