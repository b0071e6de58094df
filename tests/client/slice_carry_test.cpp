// Keyframes and points the client made after the slice's keyframe follow that keyframe's
// correction: they were tracked against the map as it was, and must stay consistent with it.
#include <gtest/gtest.h>

#include "client/slice_applier.h"
#include "geometry/sim3.h"
#include "map/map_replication.h"
#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

// A client map with the keyframe a slice answers (with points) and a newer one the edge has not
// processed yet.
struct ClientWithNewerKeyFrame {
  test::SyntheticScene scene{150, 5};
  Map client{1};
  KeyFrame* processed =
      scene.addKeyFrame(client, scene.view(test::poseAt({0, 0, 0}), 0, false), 0, true);
  KeyFrame* newer =
      scene.addKeyFrame(client, scene.view(test::poseAt({0.2, 0, 0}), 0, false), 3, false);
};

TEST(SliceCarry, NewerClientKeyFramesAndTheirPointsFollowTheProcessedKeyFrame) {
  ClientWithNewerKeyFrame t;
  test::SyntheticScene& scene = t.scene;
  Map& client = t.client;
  KeyFrame* processed = t.processed;
  KeyFrame* newer = t.newer;
  // The client triangulated a point in the newer keyframe; the edge has not heard of it.
  MapPoint* own_point = nullptr;
  {
    MutexLock lock(client.updateMutex());
    own_point = client.createMapPoint({0.3, 0.1, 3.0}, newer);
    client.addObservation(own_point, newer, 0);
  }
  MapPoint* edge_point = processed->point(1);
  ASSERT_NE(edge_point, nullptr);

  const SE3d before = processed->pose();
  const SE3d after = SE3d(Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                          Eigen::Vector3d(0.05, -0.01, 0.02)) *
                     before;
  const SE3d newer_before = newer->pose();
  const Eigen::Vector3d own_before = own_point->position();
  const Eigen::Vector3d edge_point_before = edge_point->position();

  MapSlice slice;
  slice.sequence = 1;
  slice.processed_keyframe = processed->id();
  slice.newest_keyframe = processed->id();
  slice.keyframe_poses.push_back({processed->id(), after, kInvalidId});
  const SliceApplyResult applied = applySlice(client, slice, scene.camera(), Sensor::kRgbd);

  EXPECT_EQ(applied.keyframes_carried, 1u);
  // The newer keyframe keeps its pose relative to the processed one.
  const SE3d relative_before = newer_before * before.inverse();
  const SE3d relative_after = newer->pose() * processed->pose().inverse();
  EXPECT_LT((relative_before.translation() - relative_after.translation()).norm(), 1e-9);
  EXPECT_LT(relative_before.rotation().angularDistance(relative_after.rotation()), 1e-9);
  // Its own point keeps its place in the processed keyframe's camera frame.
  EXPECT_LT(((after * own_point->position()) - (before * own_before)).norm(), 1e-9);
  // A point the edge knows is the edge's to move: untouched without a record.
  EXPECT_LT((edge_point->position() - edge_point_before).norm(), 1e-12);
}

// A loop correction (or a merge of two parts of the map, which may move the client's part by
// metres) answers no upload: the keyframes newer than the newest the edge had follow that one.
TEST(SliceCarry, AfterALoopCorrectionNewerKeyFramesFollowTheNewestTheEdgeHad) {
  ClientWithNewerKeyFrame t;
  const SE3d before = t.processed->pose();
  const SE3d after = SE3d(Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitY()).toRotationMatrix(),
                          Eigen::Vector3d(1.5, -0.2, 0.7)) *
                     before;
  const SE3d newer_before = t.newer->pose();
  MapSlice slice;
  slice.sequence = 1;
  slice.loops_closed = 1;
  slice.newest_keyframe = t.processed->id();
  slice.keyframe_poses.push_back({t.processed->id(), after, kInvalidId});
  const SliceApplyResult applied = applySlice(t.client, slice, t.scene.camera(), Sensor::kRgbd);
  EXPECT_EQ(applied.keyframes_carried, 1u);
  const SE3d relative_before = newer_before * before.inverse();
  const SE3d relative_after = t.newer->pose() * t.processed->pose().inverse();
  EXPECT_LT((relative_before.translation() - relative_after.translation()).norm(), 1e-9);
  EXPECT_LT(relative_before.rotation().angularDistance(relative_after.rotation()), 1e-9);

  // A slice that closes no loop and answers no upload carries nothing (a global BA's moves are
  // the edge's own, for the keyframes it has).
  ClientWithNewerKeyFrame u;
  const SE3d u_newer_before = u.newer->pose();
  MapSlice plain;
  plain.sequence = 1;
  plain.newest_keyframe = u.processed->id();
  plain.keyframe_poses.push_back({u.processed->id(), after, kInvalidId});
  EXPECT_EQ(applySlice(u.client, plain, u.scene.camera(), Sensor::kRgbd).keyframes_carried, 0u);
  EXPECT_LT((u.newer->pose().translation() - u_newer_before.translation()).norm(), 1e-12);
}

// A monocular loop or merge moves the client's part by a similarity: its scale changes too. The
// keyframes and points the edge has not seen follow the whole similarity, scale included (the
// client measures it on the anchor's points), or they sit at the old scale among the new.
TEST(SliceCarry, AMonocularMergeCarriesNewerKeyFramesWithItsScale) {
  for (const double scale : {0.5, 1.8}) {
    ClientWithNewerKeyFrame t;
    MapPoint* own_point = nullptr;
    {
      MutexLock lock(t.client.updateMutex());
      own_point = t.client.createMapPoint({0.3, 0.1, 3.0}, t.newer);
      t.client.addObservation(own_point, t.newer, 0);
    }
    // New world point = world * old world point.
    const Sim3d world(scale, Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())),
                      Eigen::Vector3d(1.2, -0.3, 0.4));
    const Eigen::Vector3d own_before = own_point->position();
    const SE3d newer_before = t.newer->pose();
    MapSlice slice;
    slice.sequence = 1;
    slice.loops_closed = 1;
    slice.newest_keyframe = t.processed->id();
    slice.keyframe_poses.push_back(
        {t.processed->id(), (Sim3d(t.processed->pose()) * world.inverse()).toSE3(), kInvalidId});
    for (const MapPoint* p : t.processed->points()) {
      if (p != nullptr && p != own_point)
        slice.point_positions.push_back({p->id(), world * p->position()});
    }
    ASSERT_GE(slice.point_positions.size(), 20u);

    const SliceApplyResult applied =
        applySlice(t.client, slice, t.scene.camera(), Sensor::kMonocular);
    EXPECT_EQ(applied.keyframes_carried, 1u);
    EXPECT_NEAR(applied.carry_scale, scale, 1e-9);
    const SE3d newer_expected = (Sim3d(newer_before) * world.inverse()).toSE3();
    EXPECT_LT((t.newer->pose().translation() - newer_expected.translation()).norm(), 1e-9);
    EXPECT_LT(t.newer->pose().rotation().angularDistance(newer_expected.rotation()), 1e-9);
    EXPECT_LT((own_point->position() - world * own_before).norm(), 1e-9);
  }
}

// With metric depth a loop moves rigidly whatever the points say.
TEST(SliceCarry, AnRgbdLoopCarriesRigidly) {
  ClientWithNewerKeyFrame t;
  const Sim3d world(0.5, Eigen::Quaterniond::Identity(), Eigen::Vector3d(1.0, 0, 0));
  MapSlice slice;
  slice.sequence = 1;
  slice.loops_closed = 1;
  slice.newest_keyframe = t.processed->id();
  const SE3d before = t.processed->pose();
  const SE3d newer_before = t.newer->pose();
  slice.keyframe_poses.push_back(
      {t.processed->id(), (Sim3d(before) * world.inverse()).toSE3(), kInvalidId});
  for (const MapPoint* p : t.processed->points()) {
    if (p != nullptr) slice.point_positions.push_back({p->id(), world * p->position()});
  }
  const SliceApplyResult applied = applySlice(t.client, slice, t.scene.camera(), Sensor::kRgbd);
  EXPECT_EQ(applied.carry_scale, 1.0);
  const SE3d relative_before = newer_before * before.inverse();
  const SE3d relative_after = t.newer->pose() * t.processed->pose().inverse();
  EXPECT_LT((relative_before.translation() - relative_after.translation()).norm(), 1e-9);
}

TEST(SliceCarry, ANewerKeyFrameThatTheSliceMovesKeepsTheEdgesPose) {
  ClientWithNewerKeyFrame t;
  const SE3d processed_after =
      SE3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.03, 0, 0)) * t.processed->pose();
  const SE3d newer_from_edge =
      SE3d(Eigen::Quaterniond::Identity(), Eigen::Vector3d(0, 0.04, 0)) * t.newer->pose();
  MapSlice slice;
  slice.sequence = 1;
  slice.processed_keyframe = t.processed->id();
  slice.keyframe_poses.push_back({t.processed->id(), processed_after, kInvalidId});
  slice.keyframe_poses.push_back({t.newer->id(), newer_from_edge, kInvalidId});
  const SliceApplyResult applied = applySlice(t.client, slice, t.scene.camera(), Sensor::kRgbd);
  EXPECT_EQ(applied.keyframes_carried, 0u);
  EXPECT_LT((t.newer->pose().translation() - newer_from_edge.translation()).norm(), 1e-12);
}

TEST(SliceCarry, NothingIsCarriedWhenTheProcessedKeyFrameDidNotMove) {
  ClientWithNewerKeyFrame t;
  KeyFrame* newer = t.newer;
  const SE3d newer_before = newer->pose();
  MapSlice slice;
  slice.sequence = 1;
  slice.processed_keyframe = t.processed->id();
  const SliceApplyResult applied = applySlice(t.client, slice, t.scene.camera(), Sensor::kRgbd);
  EXPECT_EQ(applied.keyframes_carried, 0u);
  EXPECT_LT((newer->pose().translation() - newer_before.translation()).norm(), 1e-12);
}

}  // namespace
}  // namespace edgeslam
