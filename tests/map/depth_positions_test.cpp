// RGB-D uploads leave out the positions of points that are the depth back-projection of their
// keypoint in the uploaded keyframe; the edge rebuilds them from the keyframe record.
#include <gtest/gtest.h>

#include "map/map_replication.h"
#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

struct DepthKeyFrame {
  test::SyntheticScene scene{150, 21};
  Map map;
  KeyFrame* kf = nullptr;

  DepthKeyFrame() {
    const auto view = scene.view(test::poseAt({0.1, -0.05, 0.1}, 0.05), 0, true);
    kf = scene.addKeyFrame(map, view, 0, false);
    // As the RGB-D tracker makes them: each keypoint back-projected at its depth.
    const FrameFeatures& f = kf->features();
    for (std::size_t i = 0; i < f.size(); ++i) {
      const Eigen::Vector3d x =
          scene.camera().unproject({f.keypoints[i].pt.x, f.keypoints[i].pt.y});
      MapPoint* p =
          map.createMapPoint(kf->poseInverse() * (x * static_cast<double>(f.depth[i])), kf);
      map.addObservation(p, kf, i);
    }
  }
};

TEST(DepthPositions, PointsMadeFromDepthAreRecognisedAndRebuilt) {
  DepthKeyFrame t;
  MutexLock lock(t.map.updateMutex());
  const std::vector<MapPoint*> points = t.map.mapPoints();
  ASSERT_GT(points.size(), 50u);
  std::vector<MapPointRecord> records;
  for (MapPoint* p : points) {
    ASSERT_TRUE(isDepthBackProjection(*p, *t.kf, t.scene.camera())) << p->id();
    MapPointRecord record = mapPointRecord(*p);
    record.position_from_depth = true;
    record.position.setZero();
    records.push_back(record);
  }
  rebuildPositionsFromDepth(records, keyFrameRecord(*t.kf), t.scene.camera());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_LT((records[i].position - points[i]->position()).norm(), 1e-5) << i;
  }
}

TEST(DepthPositions, MovedPointsAndOtherKeyFramesAreNotFlagged) {
  DepthKeyFrame t;
  MutexLock lock(t.map.updateMutex());
  MapPoint* moved = t.map.mapPoints().front();
  t.map.setPointPosition(moved, moved->position() + Eigen::Vector3d(0.0, 0.0, 0.01));
  EXPECT_FALSE(isDepthBackProjection(*moved, *t.kf, t.scene.camera()));

  const auto other_view = t.scene.view(test::poseAt({0.0, 0.0, 0.0}), 0, true);
  KeyFrame* other = t.scene.addKeyFrame(t.map, other_view, 1, false);
  MapPoint* seen_before = t.map.mapPoints().back();
  EXPECT_FALSE(isDepthBackProjection(*seen_before, *other, t.scene.camera()));
}

TEST(DepthPositions, RebuildRefusesWhatTheKeyFrameCannotGive) {
  DepthKeyFrame t;
  MutexLock lock(t.map.updateMutex());
  const KeyFrameRecord keyframe = keyFrameRecord(*t.kf);
  MapPointRecord point = mapPointRecord(*t.map.mapPoints().front());
  point.position_from_depth = true;

  std::vector<MapPointRecord> elsewhere{point};
  elsewhere[0].observations.front().keyframe = keyframe.id + 1;
  EXPECT_THROW(rebuildPositionsFromDepth(elsewhere, keyframe, t.scene.camera()),
               std::invalid_argument);

  KeyFrameRecord no_depth = keyframe;
  no_depth.features.depth[point.observations.front().keypoint_index] = -1.f;
  std::vector<MapPointRecord> one{point};
  EXPECT_THROW(rebuildPositionsFromDepth(one, no_depth, t.scene.camera()), std::invalid_argument);

  std::vector<MapPointRecord> unobserved{point};
  unobserved[0].observations.clear();
  EXPECT_THROW(rebuildPositionsFromDepth(unobserved, keyframe, t.scene.camera()),
               std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
