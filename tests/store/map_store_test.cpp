// The SQLite map store with a real (synthetic-scene) map: written through the writer as the map
// changes, read back record for record, and loaded into a Map again.
#include "store/map_store.h"

#include <gtest/gtest.h>

#include "map/map_replication.h"
#include "store/map_store_writer.h"
#include "store/store_error.h"
#include "store/stored_map_loader.h"
#include "store_fixture.h"

namespace edgeslam {
namespace {

using test::freshStoreDir;
using test::SmallMap;

const StoredSession& onlySession(const StoredMap& map) {
  EXPECT_EQ(map.sessions.size(), 1u);
  return map.sessions.front();
}

TEST(MapStore, RoundTripKeepsKeyFramesPointsAndObservations) {
  const auto dir = freshStoreDir("roundtrip");
  SmallMap small;
  {
    std::shared_ptr<MapStore> store = openMapStore(dir, MapStoreAccess::kServe);
    const StoreSessionId session = store->beginSession("kitchen", small.info());
    auto stats = std::make_shared<MapStoreWriteStats>();
    MapStoreWriter writer(store, session, small.map, stats);
    {
      MutexLock lock(small.map.updateMutex());
      writer.onMapChanged(small.map.takeChanges());
    }
    writer.stop();
    EXPECT_EQ(stats->totals().keyframes_written, 3u);
    MutexLock lock(small.map.updateMutex());
    EXPECT_EQ(stats->totals().points_written, small.map.pointCount());
  }
  MutexLock small_lock(small.map.updateMutex());  // its writer is gone
  auto store = openMapStore(dir, MapStoreAccess::kRead);
  const auto info = store->mapInfo("kitchen");
  ASSERT_TRUE(info);
  EXPECT_EQ(info->keyframes, 3u);
  EXPECT_EQ(info->points, small.map.pointCount());
  EXPECT_EQ(info->sessions, 1u);
  EXPECT_GT(info->bytes, 3u * 32u * 50u);
  const auto stored = store->loadMap("kitchen");
  ASSERT_TRUE(stored);
  const StoredSession& session = onlySession(*stored);
  EXPECT_GT(session.ended, 0.0);
  EXPECT_EQ(session.info.sensor, Sensor::kRgbd);
  EXPECT_DOUBLE_EQ(session.info.camera.fx(), small.scene.camera().fx());
  ASSERT_EQ(session.keyframes.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const KeyFrameRecord& k = session.keyframes[i];
    const KeyFrame& original = *small.keyframes[i];
    EXPECT_EQ(k.id, original.id());
    EXPECT_EQ(k.frame_index, original.frameIndex());
    EXPECT_LT((k.T_cw.translation() - original.pose().translation()).norm(), 1e-12);
    EXPECT_LT(k.T_cw.rotation().angularDistance(original.pose().rotation()), 1e-9);
    ASSERT_EQ(k.features.keypoints.size(), original.features().keypoints.size());
    EXPECT_EQ(k.features.keypoints[5].pt, original.features().keypoints[5].pt);
    EXPECT_EQ(k.features.keypoints[5].octave, original.features().keypoints[5].octave);
    EXPECT_EQ(cv::norm(k.features.descriptors, original.features().descriptors, cv::NORM_HAMMING),
              0.0);
    EXPECT_EQ(k.features.depth, original.features().depth);
    for (std::size_t j = 0; j < original.size(); ++j) {
      const MapPoint* p = original.point(j);
      EXPECT_EQ(k.point_ids[j], p != nullptr ? p->id() : kInvalidId);
    }
  }
  ASSERT_EQ(session.points.size(), small.map.pointCount());
  for (const MapPointRecord& p : session.points) {
    const MapPoint* original = small.map.mapPoint(p.id);
    ASSERT_NE(original, nullptr);
    EXPECT_EQ(p.position, original->position());
    EXPECT_EQ(p.observations.size(), original->observations().size());
  }

  // And into a Map again, as a server would hold it: covisibility rebuilt from the points.
  Map loaded;
  loadStoredSession(session, loaded);
  MutexLock loaded_lock(loaded.updateMutex());
  EXPECT_EQ(loaded.keyFrameCount(), 3u);
  EXPECT_EQ(loaded.pointCount(), small.map.pointCount());
  const KeyFrame* a = loaded.keyFrame(small.keyframes[0]->id());
  const KeyFrame* b = loaded.keyFrame(small.keyframes[1]->id());
  ASSERT_NE(a, nullptr);
  ASSERT_NE(b, nullptr);
  EXPECT_EQ(a->weight(const_cast<KeyFrame*>(b)), small.keyframes[0]->weight(small.keyframes[1]));
  EXPECT_GT(a->weight(const_cast<KeyFrame*>(b)), 10);
  // New ids continue after the loaded ones.
  EXPECT_GT(loaded.ids().next(), small.map.mapPoints().back()->id());
  std::filesystem::remove_all(dir);
}

TEST(MapStore, LaterBatchesUpdatePosesAndEraseWhatTheMapErased) {
  const auto dir = freshStoreDir("updates");
  SmallMap small;
  std::shared_ptr<MapStore> store = openMapStore(dir, MapStoreAccess::kServe);
  const StoreSessionId session = store->beginSession("m", small.info());
  MapStoreWriter writer(store, session, small.map, nullptr);
  const auto take = [&] {
    MutexLock lock(small.map.updateMutex());
    writer.onMapChanged(small.map.takeChanges());
  };
  take();
  writer.flush();
  KeyFrame* moved = small.keyframes[2];
  const SE3d corrected(Eigen::Quaterniond::Identity(), Eigen::Vector3d(1, 2, 3));
  MapPoint* doomed = small.keyframes[0]->goodPoints().front();
  const MapPointId doomed_id = doomed->id();
  MapPoint* shifted = nullptr;
  Eigen::Vector3d shifted_to;
  {
    MutexLock lock(small.map.updateMutex());
    small.map.setKeyFramePose(moved, corrected);
    small.map.erasePoint(doomed);
    shifted = small.keyframes[1]->goodPoints().back();
    shifted_to = shifted->position() + Eigen::Vector3d(0.5, 0, 0);
    small.map.relocatePoint(shifted, shifted_to);
  }
  take();
  writer.flush();
  const StoredSession loaded = onlySession(*store->loadMap("m"));
  {
    MutexLock lock(small.map.updateMutex());
    EXPECT_EQ(loaded.points.size(), small.map.pointCount());
  }
  for (const MapPointRecord& p : loaded.points) {
    EXPECT_NE(p.id, doomed_id);
    if (p.id == shifted->id()) {
      EXPECT_EQ(p.position, shifted_to);                                 // moved in place...
      EXPECT_EQ(p.observations.size(), shifted->observations().size());  // ...the rest kept
    }
  }
  EXPECT_EQ(loaded.keyframes[2].T_cw.translation(), Eigen::Vector3d(1, 2, 3));

  // A failed start empties the session's map.
  writer.onMapCleared();
  writer.flush();
  const StoredSession cleared = onlySession(*store->loadMap("m"));
  EXPECT_TRUE(cleared.keyframes.empty());
  EXPECT_TRUE(cleared.points.empty());
  writer.stop();
  std::filesystem::remove_all(dir);
}

// A server restarted on its store resumes a session: the map loaded back, written on into the
// same stored session; a loaded keyframe culled later is deleted, not left behind.
TEST(MapStore, ResumedSessionIsWrittenOnInPlace) {
  const auto dir = freshStoreDir("resume");
  SmallMap small;
  std::shared_ptr<MapStore> store = openMapStore(dir, MapStoreAccess::kServe);
  const StoreSessionId session = store->beginSession("m", small.info());
  {
    MapStoreWriter writer(store, session, small.map, nullptr);
    MutexLock lock(small.map.updateMutex());
    writer.onMapChanged(small.map.takeChanges());
  }  // stopped: written, session ended
  const StoredSession stored = onlySession(*store->loadMap("m"));
  EXPECT_GT(stored.ended, 0.0);
  Map resumed;
  loadStoredSession(stored, resumed);
  store->resumeSession(stored.id);
  EXPECT_EQ(onlySession(*store->loadMap("m")).ended, 0.0);
  MapStoreWriter writer(store, stored.id, resumed, nullptr);
  std::vector<KeyFrameId> ids;
  for (const KeyFrameRecord& k : stored.keyframes) ids.push_back(k.id);
  writer.assumeStored(ids);
  {
    MutexLock lock(resumed.updateMutex());
    KeyFrame* culled = resumed.keyFrame(stored.keyframes[1].id);
    ASSERT_NE(culled, nullptr);
    resumed.eraseKeyFrame(culled);
    writer.onMapChanged(resumed.takeChanges());
  }
  writer.stop();
  const StoredMap after = *store->loadMap("m");
  const StoredSession& again = onlySession(after);
  EXPECT_EQ(again.id, stored.id);
  ASSERT_EQ(again.keyframes.size(), 2u);
  for (const KeyFrameRecord& k : again.keyframes) EXPECT_NE(k.id, stored.keyframes[1].id);
  EXPECT_GT(again.ended, 0.0);
  std::filesystem::remove_all(dir);
}

TEST(MapStore, NamedMapsLiveSideBySideAndRemoveAlone) {
  const auto dir = freshStoreDir("named");
  SmallMap small;
  MutexLock lock(small.map.updateMutex());
  auto store = openMapStore(dir, MapStoreAccess::kServe);
  MapStoreBatch batch;
  for (const KeyFrame* kf : small.map.keyFrames()) batch.keyframes.push_back(keyFrameRecord(*kf));
  for (const MapPoint* p : small.map.mapPoints()) batch.points.push_back(mapPointRecord(*p));
  store->write(store->beginSession("office", small.info()), batch);
  store->write(store->beginSession("kitchen", small.info()), batch);
  store->write(store->beginSession("kitchen", small.info()), batch);
  const auto maps = store->listMaps();
  ASSERT_EQ(maps.size(), 2u);
  EXPECT_EQ(maps[0].name, "kitchen");
  EXPECT_EQ(maps[0].sessions, 2u);
  EXPECT_EQ(maps[0].keyframes, 6u);
  EXPECT_EQ(maps[1].name, "office");
  EXPECT_EQ(maps[1].keyframes, 3u);
  EXPECT_TRUE(store->removeMap("kitchen"));
  EXPECT_FALSE(store->removeMap("kitchen"));
  EXPECT_FALSE(store->mapInfo("kitchen"));
  EXPECT_EQ(store->mapInfo("office")->points, small.map.pointCount());
  std::filesystem::remove_all(dir);
}

TEST(MapStore, AMapIsMetricOnceASessionMeasuredDepth) {
  const auto dir = freshStoreDir("metric");
  SmallMap small;
  auto store = openMapStore(dir, MapStoreAccess::kServe);
  StoredSessionInfo mono = small.info();
  mono.sensor = Sensor::kMonocular;
  store->beginSession("walk", mono);
  EXPECT_FALSE(store->mapInfo("walk")->metric);  // monocular only: no metric scale
  store->beginSession("walk", small.info());     // RGB-D
  EXPECT_TRUE(store->mapInfo("walk")->metric);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace edgeslam
