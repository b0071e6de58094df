#pragma once
// A small real map (synthetic scene: keyframes with features, depth and points) and a fresh store
// folder per test.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "map/map_replication.h"
#include "map/synthetic_views.h"
#include "store/map_store.h"
#include "store/map_store_writer.h"
#include "support/fresh_temp_dir.h"

namespace edgeslam::test {

inline std::filesystem::path freshStoreDir(const std::string& name) {
  return freshTempDir("store_" + name);
}

struct SmallMap {
  SyntheticScene scene;
  Map map;
  std::vector<KeyFrame*> keyframes;

  explicit SmallMap(int scene_points = 400) : scene(scene_points, 3) {
    for (int i = 0; i < 3; ++i) {
      const auto view = scene.view(poseAt({0.15 * i, 0.02 * i, 0}, 0.03 * i), 0, true);
      KeyFrame* kf = scene.addKeyFrame(map, view, static_cast<std::size_t>(10 * i), i == 0);
      if (i > 0) {
        // Link this view's keypoints to the first keyframe's points of the same scene point.
        for (std::size_t k = 0; k < view.scene_point.size(); ++k) {
          for (MapPoint* p : keyframes[0]->points()) {
            if (p != nullptr && scene.sceneOf(p) == view.scene_point[k]) {
              map.addObservation(p, kf, k);
              break;
            }
          }
        }
      }
      keyframes.push_back(kf);
    }
    for (MapPoint* p : map.mapPoints()) map.refreshPoint(p);
    for (KeyFrame* kf : keyframes) map.updateConnections(kf);
  }

  StoredSessionInfo info() const { return {"test-client", scene.camera(), Sensor::kRgbd}; }
};

// A SmallMap written into `store` as map `name`, one session, in one batch.
inline void writeSmallMap(MapStore& store, const std::string& name) {
  SmallMap small;
  MutexLock lock(small.map.updateMutex());
  MapStoreBatch batch;
  for (const KeyFrame* kf : small.map.keyFrames()) batch.keyframes.push_back(keyFrameRecord(*kf));
  for (const MapPoint* p : small.map.mapPoints()) batch.points.push_back(mapPointRecord(*p));
  store.write(store.beginSession(name, small.info()), batch);
}

}  // namespace edgeslam::test
