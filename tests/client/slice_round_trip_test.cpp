// Client and edge maps kept in step through records: a replica built from keyframe records, then
// edge-side changes carried by a slice, must match the original.
#include <gtest/gtest.h>

#include "client/slice_applier.h"
#include "map/map_replication.h"
#include "map/synthetic_views.h"
#include "server/slice_builder.h"
#include "support/mutex_unlock.h"

namespace edgeslam {
namespace {

struct EdgeAndClient {
  test::SyntheticScene scene{200, 11};
  Map edge{0};
  Map client{1};
  std::vector<KeyFrame*> edge_keyframes;

  EdgeAndClient() {
    // Three keyframes on the edge, sharing points through the scene's point identities.
    for (int k = 0; k < 3; ++k) {
      const auto view = scene.view(test::poseAt({0.1 * k, 0, 0}), 0, false);
      KeyFrame* kf = scene.addKeyFrame(edge, view, static_cast<std::size_t>(k), k == 0);
      if (k > 0) {
        const auto first = scene.view(test::poseAt({0, 0, 0}), 0, false);
        for (std::size_t i = 0; i < view.scene_point.size(); ++i) {
          for (std::size_t j = 0; j < first.scene_point.size(); ++j) {
            MapPoint* p = edge_keyframes[0]->point(j);
            if (first.scene_point[j] == view.scene_point[i] && p != nullptr) {
              edge.addObservation(p, kf, i);
            }
          }
        }
      }
      edge_keyframes.push_back(kf);
    }
    for (KeyFrame* kf : edge_keyframes) edge.updateConnections(kf);
    // The client receives every keyframe and point as records.
    for (KeyFrame* kf : edge_keyframes) {
      insertKeyFrameRecord(client, keyFrameRecord(*kf), scene.camera());
    }
    for (MapPoint* p : edge.mapPoints()) {
      upsertPointRecord(client, mapPointRecord(*p), edge_keyframes.back()->id());
    }
    for (KeyFrame* kf : client.keyFrames()) client.updateConnections(kf);
    edge.takeChanges();
  }
};

void expectSameMaps(const Map& a, const Map& b) REQUIRES(a.updateMutex(), b.updateMutex()) {
  ASSERT_EQ(a.keyFrameCount(), b.keyFrameCount());
  ASSERT_EQ(a.pointCount(), b.pointCount());
  for (MapPoint* p : a.mapPoints()) {
    const MapPoint* q = b.mapPoint(p->id());
    ASSERT_NE(q, nullptr) << "point " << p->id();
    EXPECT_LT((p->position() - q->position()).norm(), 1e-12);
    EXPECT_EQ(p->observations().size(), q->observations().size());
    EXPECT_EQ(cv::norm(p->descriptor(), q->descriptor(), cv::NORM_HAMMING), 0);
  }
  for (KeyFrame* kf : a.keyFrames()) {
    const KeyFrame* other = b.keyFrame(kf->id());
    ASSERT_NE(other, nullptr);
    EXPECT_LT((kf->cameraCenter() - other->cameraCenter()).norm(), 1e-12);
    EXPECT_EQ(kf->connections().size(), other->connections().size());
  }
}

TEST(SliceRoundTrip, ReplicaFromRecordsMatchesTheOriginal) {
  EdgeAndClient t;
  MutexLock edge_lock(t.edge.updateMutex());
  MutexLock client_lock(t.client.updateMutex());
  EXPECT_GT(t.edge.pointCount(), 100u);
  expectSameMaps(t.edge, t.client);
}

TEST(SliceRoundTrip, SliceCarriesMovesErasuresAndPoseCorrections) {
  EdgeAndClient t;
  MutexLock edge_lock(t.edge.updateMutex());
  MutexLock client_lock(t.client.updateMutex());
  std::vector<MapPoint*> points = t.edge.mapPoints();
  t.edge.setPointPosition(points[0], points[0]->position() + Eigen::Vector3d(0.05, 0, 0));
  t.edge.erasePoint(points[1]);
  KeyFrame* moved = t.edge_keyframes[2];
  t.edge.setKeyFramePose(moved, SE3d(Eigen::Quaterniond::Identity(), {-0.21, 0.01, 0}));
  // A new point on keypoints that had none.
  const auto free_slot = [](const KeyFrame* kf) {
    for (std::size_t i = 0; i < kf->size(); ++i) {
      if (kf->point(i) == nullptr) return i;
    }
    return kf->size();
  };
  const std::size_t slot1 = free_slot(t.edge_keyframes[1]);
  const std::size_t slot2 = free_slot(t.edge_keyframes[2]);
  ASSERT_LT(slot1, t.edge_keyframes[1]->size());
  ASSERT_LT(slot2, t.edge_keyframes[2]->size());
  MapPoint* fresh = t.edge.createMapPoint({0.1, 0.2, 3.0}, t.edge_keyframes[1]);
  t.edge.addObservation(fresh, t.edge_keyframes[1], slot1);
  t.edge.addObservation(fresh, t.edge_keyframes[2], slot2);
  t.edge.refreshPoint(fresh);

  MapSlice slice = buildSlice(t.edge, t.edge.takeChanges());
  slice.newest_keyframe = moved->id();
  EXPECT_EQ(slice.points_erased.size(), 1u);
  EXPECT_EQ(slice.keyframe_poses.size(), 1u);
  SliceApplyResult applied;
  {
    test::MutexUnlock unlock(t.client.updateMutex());  // applySlice takes it
    applied = applySlice(t.client, slice, t.scene.camera(), Sensor::kRgbd);
  }
  EXPECT_EQ(applied.points_erased, 1u);
  EXPECT_EQ(applied.keyframes_moved, 1u);
  expectSameMaps(t.edge, t.client);
  // Applying a slice is not itself a change to report back.
  EXPECT_TRUE(t.client.changes().points_updated.empty());
}

TEST(SliceRoundTrip, ObservationsInKeyFramesTheEdgeHasNotSeenSurvive) {
  EdgeAndClient t;
  MutexLock edge_lock(t.edge.updateMutex());
  MutexLock client_lock(t.client.updateMutex());
  MapPoint* p = t.edge.mapPoints().front();
  // The client links the point in a keyframe the edge has not received yet.
  const auto view = t.scene.view(test::poseAt({0.3, 0, 0}), 0, false);
  KeyFrame* newer = t.scene.addKeyFrame(t.client, view, 9, false);
  MapPoint* replica = t.client.mapPoint(p->id());
  t.client.addObservation(replica, newer, 0);
  const std::size_t before = replica->observations().size();

  t.edge.setPointPosition(p, p->position() + Eigen::Vector3d(0, 0.01, 0));
  MapSlice slice = buildSlice(t.edge, t.edge.takeChanges());
  slice.newest_keyframe = t.edge_keyframes.back()->id();
  {
    test::MutexUnlock unlock(t.client.updateMutex());  // applySlice takes it
    applySlice(t.client, slice, t.scene.camera(), Sensor::kRgbd);
  }
  EXPECT_EQ(replica->observations().size(), before);
  EXPECT_LT((replica->position() - p->position()).norm(), 1e-12);
}

TEST(SliceRoundTrip, InconsistentFeatureRecordIsRejected) {
  EdgeAndClient t;
  KeyFrameRecord record = keyFrameRecord(*t.edge_keyframes[0]);
  record.id = 12345;
  record.features.depth.resize(3);
  Map replica;
  MutexLock lock(replica.updateMutex());
  EXPECT_THROW(insertKeyFrameRecord(replica, record, t.scene.camera()), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
