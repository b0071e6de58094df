// A point a monocular client triangulated between its new keyframe and an older one, arriving on
// the edge with the new keyframe's upload: applied with both observations when the edge's map
// agrees, merged into the edge's own point when the older keypoint already holds one, and erased
// when the older keyframe is gone, each change recorded for the slices.
#include <gtest/gtest.h>

#include "map/map_replication.h"
#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

using test::poseAt;

struct UploadFixture {
  test::SyntheticScene scene{200, 3};
  Map client{1};
  Map edge{0};
  KeyFrame* origin = nullptr;  // client keyframes
  KeyFrame* older = nullptr;
  KeyFrame* uploaded = nullptr;
  std::size_t i_older = 0, i_uploaded = 0;  // keypoints of one scene point in both
  MapPoint* triangulated = nullptr;

  UploadFixture() {
    const auto v0 = scene.view(poseAt({0, 0, 0}), 0, false);
    const auto v1 = scene.view(poseAt({0.2, 0, 0}), 0, false);
    const auto v2 = scene.view(poseAt({0.4, 0, 0}), 0, false);
    origin = scene.addKeyFrame(client, v0, 0, false);
    older = scene.addKeyFrame(client, v1, 1, false);
    uploaded = scene.addKeyFrame(client, v2, 2, false);
    bool found = false;
    for (std::size_t a = 0; a < v1.scene_point.size() && !found; ++a) {
      for (std::size_t b = 0; b < v2.scene_point.size() && !found; ++b) {
        if (v1.scene_point[a] != v2.scene_point[b]) continue;
        i_older = a;
        i_uploaded = b;
        found = true;
      }
    }
    EXPECT_TRUE(found);
    const Eigen::Vector3d x = scene.points()[static_cast<std::size_t>(v2.scene_point[i_uploaded])];
    triangulated = client.createMapPoint(x, uploaded);
    client.addObservation(triangulated, uploaded, i_uploaded);
    client.addObservation(triangulated, older, i_older);
    client.refreshPoint(triangulated);
    // The edge has the client's earlier keyframes.
    insertKeyFrameRecord(edge, keyFrameRecord(*origin), scene.camera());
  }

  void edgeReceivesOlder() REQUIRES(edge.updateMutex()) {
    insertKeyFrameRecord(edge, keyFrameRecord(*older), scene.camera());
  }

  // As EdgeMapSession applies an upload: without recording, then the conflicts with recording.
  std::optional<UploadedPointConflict> upload() REQUIRES(edge.updateMutex()) {
    edge.takeChanges();
    edge.setChangeRecording(false);
    insertKeyFrameRecord(edge, keyFrameRecord(*uploaded), scene.camera());
    auto conflict = insertUploadedPoint(edge, mapPointRecord(*triangulated), uploaded->id());
    edge.setChangeRecording(true);
    if (conflict) resolveUploadedPointConflicts(edge, {*conflict});
    return conflict;
  }
};

TEST(UploadedPoint, ObservationInTheOlderKeyFrameIsApplied) {
  UploadFixture t;
  MutexLock lock(t.edge.updateMutex());
  t.edgeReceivesOlder();
  EXPECT_FALSE(t.upload().has_value());
  const MapPoint* p = t.edge.mapPoint(t.triangulated->id());
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->observations().size(), 2u);
  EXPECT_EQ(t.edge.keyFrame(t.older->id())->point(t.i_older), p);
  EXPECT_EQ(t.edge.keyFrame(t.uploaded->id())->point(t.i_uploaded), p);
  EXPECT_LT((p->position() - t.triangulated->position()).norm(), 1e-12);
  // The client has it already: nothing to send back.
  EXPECT_TRUE(t.edge.changes().empty());
}

TEST(UploadedPoint, KeypointHoldingTheEdgesOwnPointMergesIntoIt) {
  UploadFixture t;
  MutexLock lock(t.edge.updateMutex());
  t.edgeReceivesOlder();
  // The edge triangulated that keypoint itself before the client heard of it.
  KeyFrame* older_on_edge = t.edge.keyFrame(t.older->id());
  KeyFrame* origin_on_edge = t.edge.keyFrame(t.origin->id());
  MapPoint* own = t.edge.createMapPoint(t.triangulated->position(), older_on_edge);
  t.edge.addObservation(own, older_on_edge, t.i_older);
  t.edge.addObservation(own, origin_on_edge, 0);
  t.edge.refreshPoint(own);
  const auto conflict = t.upload();
  ASSERT_TRUE(conflict.has_value());
  EXPECT_EQ(conflict->occupant, own);
  EXPECT_EQ(t.edge.mapPoint(t.triangulated->id()), nullptr);
  ASSERT_FALSE(own->isBad());
  EXPECT_EQ(own->observations().size(), 3u);
  EXPECT_TRUE(own->observations().contains(t.uploaded->id()));
  EXPECT_EQ(t.edge.keyFrame(t.uploaded->id())->point(t.i_uploaded), own);
  // The slice tells the client: its point goes, the edge's point gains the keypoint.
  EXPECT_TRUE(t.edge.changes().points_erased.contains(t.triangulated->id()));
  EXPECT_TRUE(t.edge.changes().points_updated.contains(own->id()));
}

TEST(UploadedPoint, PointLeftWithOneObservationIsErasedAndTheErasureRecorded) {
  UploadFixture t;  // the older keyframe never reaches the edge (culled there meanwhile)
  MutexLock lock(t.edge.updateMutex());
  const auto conflict = t.upload();
  ASSERT_TRUE(conflict.has_value());
  EXPECT_EQ(conflict->occupant, nullptr);
  EXPECT_EQ(t.edge.mapPoint(t.triangulated->id()), nullptr);
  EXPECT_EQ(t.edge.keyFrame(t.uploaded->id())->point(t.i_uploaded), nullptr);
  EXPECT_TRUE(t.edge.changes().points_erased.contains(t.triangulated->id()));
}

TEST(UploadedPoint, ObservationInALaterKeyFrameWaitsForIt) {
  // The client's first keyframe upload carries points the second keyframe sees too.
  UploadFixture t;
  MutexLock lock(t.edge.updateMutex());
  t.edge.takeChanges();
  t.edge.setChangeRecording(false);
  insertKeyFrameRecord(t.edge, keyFrameRecord(*t.older), t.scene.camera());
  EXPECT_FALSE(insertUploadedPoint(t.edge, mapPointRecord(*t.triangulated), t.older->id()));
  const MapPoint* p = t.edge.mapPoint(t.triangulated->id());
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->observations().size(), 1u);
  insertKeyFrameRecord(t.edge, keyFrameRecord(*t.uploaded), t.scene.camera());
  t.edge.setChangeRecording(true);
  EXPECT_EQ(p->observations().size(), 2u);
  EXPECT_TRUE(t.edge.changes().empty());
}

}  // namespace
}  // namespace edgeslam
