// The edge's local mapper searches a new keyframe for the points its client created just before
// (LocalMapperOptions::observe_recent_points). A keyframe that starts a new map after its client
// was lost for good is placed at the last pose tracked, where the old map's recent points still
// project: it must not observe them, or the two maps are joined by chance before a loop can merge
// them as a whole (redkitchen, edge mode, --new-map-after 3: the new map's first keyframe
// observed old points in 3 runs of 3 with --realtime, and its loop was then corrected as a seam).
#include <gtest/gtest.h>

#include "map/synthetic_views.h"
#include "mapping/local_mapper.h"

namespace edgeslam {
namespace {

using test::poseAt;
using test::SyntheticScene;

LocalMapperOptions edgeOptions() {
  LocalMapperOptions o;
  o.monocular = false;
  o.run_local_ba = false;
  o.cull_keyframes = false;
  o.observe_recent_points = true;
  return o;
}

int pointsSeenBy(const KeyFrame& keyframe, const KeyFrame& other) {
  int seen = 0;
  for (const MapPoint* p : keyframe.goodPoints()) {
    if (p->observations().contains(other.id())) ++seen;
  }
  return seen;
}

// An edge mapper that has just mapped one keyframe of a client (its points are recent).
class RecentPoints : public ::testing::Test {
 protected:
  KeyFrame* mapFirstKeyFrame(std::size_t frame_index) {
    KeyFrame* kf = nullptr;
    {
      MutexLock lock(map.updateMutex());
      kf = scene.addKeyFrame(map, scene.view(poseAt({0, 0, 0}), 4, true), frame_index, true);
    }
    mapper.insertKeyFrame(kf);
    mapper.processAll();
    return kf;
  }

  SyntheticScene scene{400, 11};
  Map map{1};  // a client's keyframes, as on the edge
  LocalMapper mapper{map, scene.camera(), edgeOptions()};
};

TEST_F(RecentPoints, AKeyFrameStartingANewMapDoesNotObserveTheOldMapsRecentPoints) {
  KeyFrame* last_of_old = mapFirstKeyFrame(200);

  // The new map's first keyframe, at nearly the same pose, with points of its own only.
  KeyFrame* first_of_new = nullptr;
  {
    MutexLock lock(map.updateMutex());
    first_of_new =
        scene.addKeyFrame(map, scene.view(poseAt({0.02, 0, 0.01}, 0.01), 4, true), 293, true);
    map.updateConnections(first_of_new);
    ASSERT_TRUE(first_of_new->connections().empty());
  }
  mapper.insertKeyFrame(first_of_new);
  mapper.processAll();

  MutexLock lock(map.updateMutex());
  EXPECT_EQ(pointsSeenBy(*first_of_new, *last_of_old), 0);
  EXPECT_FALSE(first_of_new->connections().contains(last_of_old));
}

TEST_F(RecentPoints, AKeyFrameOfTheSameMapObservesThemStill) {
  KeyFrame* previous = mapFirstKeyFrame(10);

  // The next keyframe tracked a few of the previous one's points (its client did not have the
  // rest yet): mapping it finds the others.
  KeyFrame* next = nullptr;
  int tracked = 0;
  {
    MutexLock lock(map.updateMutex());
    const test::SyntheticView view = scene.view(poseAt({0.03, 0, 0.02}, 0.01), 4, true);
    next = scene.addKeyFrame(map, view, 11, false);
    for (std::size_t i = 0; i < view.scene_point.size() && tracked < 30; ++i) {
      for (std::size_t j = 0; j < previous->size(); ++j) {
        MapPoint* p = previous->point(j);
        if (p != nullptr && scene.sceneOf(p) == view.scene_point[i]) {
          map.addObservation(p, next, i);
          ++tracked;
          break;
        }
      }
    }
    map.updateConnections(next);
    ASSERT_EQ(tracked, 30);
  }
  mapper.insertKeyFrame(next);
  mapper.processAll();

  MutexLock lock(map.updateMutex());
  EXPECT_GT(pointsSeenBy(*next, *previous), 2 * tracked);
}

}  // namespace
}  // namespace edgeslam
