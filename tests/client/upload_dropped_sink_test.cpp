// A keyframe whose upload the link dropped is forgotten by the client with the points that went
// up with it; points the edge knows stay.
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <vector>

#include "client/edge_keyframe_sink.h"
#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

class KeepingUplink final : public KeyFrameUplink {
 public:
  void send(KeyFrameUpload upload) override { sent.push_back(std::move(upload)); }
  std::vector<KeyFrameUpload> sent;
};

std::vector<MapPointId> newPointIds(const KeyFrameUpload& upload) {
  std::vector<MapPointId> ids;
  for (const MapPointRecord& p : upload.new_points) ids.push_back(p.id);
  return ids;
}

// A monocular client's map (id origin 1): keyframes along a line looking at one scene, each
// seeing every scene point visible from all of them.
class DroppedUploadSink : public ::testing::Test {
 protected:
  DroppedUploadSink() : scene(80, 7), map(1), sink(map, uplink) {
    for (int k = 0; k < 4; ++k) {
      views.push_back(scene.view(test::poseAt({0.1 * k, 0.0, 0.0}), 0, false));
    }
    for (int s = 0; s < static_cast<int>(scene.points().size()); ++s) {
      if (std::all_of(views.begin(), views.end(), [&](const test::SyntheticView& v) {
            return std::find(v.scene_point.begin(), v.scene_point.end(), s) != v.scene_point.end();
          })) {
        common.push_back(s);
      }
    }
  }

  std::size_t indexOf(std::size_t view, int scene_point) const {
    const auto& sp = views[view].scene_point;
    return static_cast<std::size_t>(std::find(sp.begin(), sp.end(), scene_point) - sp.begin());
  }

  KeyFrame* keyframe(std::size_t view) {
    MutexLock lock(map.updateMutex());
    return map.createKeyFrame(view, 0.0, views[view].features, views[view].T_cw);
  }

  // A point at scene point `scene_point`, born in `born`, observed by `observers`.
  MapPoint* point(int scene_point, KeyFrame* born, const std::vector<KeyFrame*>& observers) {
    MutexLock lock(map.updateMutex());
    MapPoint* p = map.createMapPoint(scene.points()[static_cast<std::size_t>(scene_point)], born);
    scene_of[p] = scene_point;
    for (KeyFrame* kf : observers)
      map.addObservation(p, kf, indexOf(kf->frameIndex(), scene_point));
    map.refreshPoint(p);
    return p;
  }

  void observe(MapPoint* p, KeyFrame* kf) {
    MutexLock lock(map.updateMutex());
    map.addObservation(p, kf, indexOf(kf->frameIndex(), scene_of.at(p)));
  }

  void connect(std::initializer_list<KeyFrame*> keyframes) {
    MutexLock lock(map.updateMutex());
    for (KeyFrame* kf : keyframes) map.updateConnections(kf);
  }

  test::SyntheticScene scene;
  std::vector<test::SyntheticView> views;
  std::vector<int> common;  // scene points every view sees
  std::map<const MapPoint*, int> scene_of;
  Map map;
  KeepingUplink uplink;
  EdgeKeyFrameSink sink;
};

TEST_F(DroppedUploadSink, ForgetsTheKeyFrameAndItsOwnPointsButKeepsThoseTheEdgeKnows) {
  ASSERT_GE(common.size(), 12u);
  KeyFrame* kf0 = keyframe(0);
  KeyFrame* kf1 = keyframe(1);
  // Known to the edge: uploaded with kf0 and kf1. `thin` is seen by one other keyframe only,
  // which erasing kf2 the usual way would cull.
  std::vector<MapPoint*> known;
  for (std::size_t i = 0; i < 4; ++i) known.push_back(point(common[i], kf0, {kf0, kf1}));
  MapPoint* thin = point(common[4], kf0, {kf0});
  connect({kf0, kf1});
  sink.insertKeyFrame(kf0);
  sink.insertKeyFrame(kf1);

  KeyFrame* kf2 = keyframe(2);
  std::vector<MapPoint*> own;  // born in kf2, triangulated with kf1: went up with kf2 only
  for (std::size_t i = 5; i < 9; ++i) own.push_back(point(common[i], kf2, {kf2, kf1}));
  // Born in kf2 and seen by two more keyframes: not culled by losing one observation.
  KeyFrame* kf3 = keyframe(3);
  MapPoint* own_well_seen = point(common[9], kf2, {kf2, kf1, kf3});
  for (MapPoint* p : known) observe(p, kf2);
  observe(thin, kf2);
  connect({kf1, kf2, kf3});
  sink.insertKeyFrame(kf2);
  ASSERT_EQ(uplink.sent.size(), 3u);
  std::vector<MapPointId> sent_with_kf2 = newPointIds(uplink.sent[2]);
  std::sort(sent_with_kf2.begin(), sent_with_kf2.end());
  std::vector<MapPointId> own_ids;
  for (MapPoint* p : own) own_ids.push_back(p->id());
  own_ids.push_back(own_well_seen->id());
  std::sort(own_ids.begin(), own_ids.end());
  ASSERT_EQ(sent_with_kf2, own_ids);
  EXPECT_EQ(sink.uploadsInFlight(), 3u);

  const KeyFrameId kf2_id = kf2->id();
  EXPECT_TRUE(sink.onUploadDropped(3, kf2_id));

  MutexLock lock(map.updateMutex());
  EXPECT_EQ(map.keyFrame(kf2_id), nullptr);
  EXPECT_TRUE(kf2->isBad());
  for (MapPoint* p : own) EXPECT_TRUE(p->isBad());
  EXPECT_TRUE(own_well_seen->isBad()) << "went up with the dropped upload only";
  EXPECT_EQ(map.mapPoint(own_well_seen->id()), nullptr);
  for (MapPoint* p : known) {
    EXPECT_FALSE(p->isBad());
    EXPECT_FALSE(p->observations().contains(kf2_id));
    EXPECT_EQ(p->observations().size(), 2u);
  }
  EXPECT_FALSE(thin->isBad()) << "the edge knows it: it keeps its last observation";
  EXPECT_EQ(thin->observations().size(), 1u);
  EXPECT_EQ(kf1->weight(kf2), 0);
  EXPECT_EQ(kf3->weight(kf1), 0) << "they shared only points that went with kf2";
  EXPECT_EQ(sink.keyFramesForgotten(), 1u);
  EXPECT_EQ(sink.pointsForgotten(), own.size() + 1);
  EXPECT_EQ(sink.uploadsInFlight(), 2u) << "a dropped upload is never answered";
}

TEST_F(DroppedUploadSink, AnswerOfALaterUploadSettlesTheDroppedOnes) {
  KeyFrame* kf0 = keyframe(0);
  KeyFrame* kf1 = keyframe(1);
  KeyFrame* kf2 = keyframe(2);
  for (KeyFrame* kf : {kf0, kf1, kf2}) sink.insertKeyFrame(kf);
  EXPECT_FALSE(sink.allAnswered());
  EXPECT_TRUE(sink.onUploadDropped(2, kf1->id()));
  EXPECT_EQ(sink.uploadsInFlight(), 2u);
  sink.onSliceApplied(1, 0);
  EXPECT_EQ(sink.uploadsInFlight(), 1u);
  sink.onSliceApplied(3, 2);
  EXPECT_TRUE(sink.allAnswered());
  EXPECT_FALSE(sink.onUploadDropped(2, kf1->id())) << "already forgotten";
  EXPECT_EQ(sink.keyFramesForgotten(), 1u);
}

TEST_F(DroppedUploadSink, TheOriginKeepsItsPoseAndAResetIsSaidAgain) {
  sink.onMapReset();
  KeyFrame* kf0 = keyframe(0);
  {
    MutexLock lock(map.updateMutex());
    ASSERT_EQ(map.originKeyFrame(), kf0);
  }
  MapPoint* own = point(common[0], kf0, {kf0});
  sink.insertKeyFrame(kf0);
  ASSERT_TRUE(uplink.sent.back().map_reset);
  EXPECT_TRUE(sink.onUploadDropped(uplink.sent.back().sequence, kf0->id()));
  {
    MutexLock lock(map.updateMutex());
    EXPECT_EQ(map.keyFrame(kf0->id()), kf0);
    EXPECT_TRUE(kf0->isEvicted());
    EXPECT_EQ(map.heldKeyFrameCount(), 0u);
    EXPECT_TRUE(own->isBad());
  }
  // The edge never heard of the new map: the next upload says so again.
  sink.insertKeyFrame(keyframe(1));
  EXPECT_TRUE(uplink.sent.back().map_reset);
}

}  // namespace
}  // namespace edgeslam
