// The edge maps the keyframes of every client of a shared map on one local mapper, in arrival
// order. As in ORB-SLAM, a keyframe whose client has already sent the next one is mapped in
// short (no fusion, no local BA, triangulation cut at its first points): that client is ahead and
// needs the next one mapped. Another client's waiting keyframe must not cut it short: with two
// monocular clients mapping redkitchen at once, the interleaving did, and the second client
// tracked ~50 points where it tracked ~150 alone (a third of the runs ended >20 % off).
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
  o.run_local_ba = true;
  o.cull_keyframes = false;
  return o;
}

class LocalMapperClients : public ::testing::Test {
 protected:
  // A keyframe of client `origin` (its ids carry it, as uploads do) with points of its own.
  KeyFrame* keyFrameOf(std::uint8_t origin, std::size_t frame_index, double x) {
    MutexLock lock(map.updateMutex());
    const test::SyntheticView view = scene.view(poseAt({x, 0, 0}), 4, true);
    const KeyFrameId id = (static_cast<std::uint64_t>(origin) << 56) | ++next_id[origin];
    KeyFrame* kf = map.createKeyFrame(frame_index, 0.0, view.features, view.T_cw, id);
    for (std::size_t i = 0; i < view.scene_point.size(); ++i) {
      MapPoint* p = map.createMapPoint(scene.points()[view.scene_point[i]], kf);
      map.addObservation(p, kf, i);
      map.refreshPoint(p);
    }
    return kf;
  }

  // Client 1's first two keyframes mapped, each in full.
  void SetUp() override {
    for (std::size_t frame : {0u, 10u}) mapper.insertKeyFrame(keyFrameOf(1, frame, 0.01 * frame));
    mapper.processAll();
    ba_before = mapper.stats().local_ba_runs;
  }

  // Keyframes mapped in full (with their local BA) since SetUp.
  std::size_t mappedInFull() const { return mapper.stats().local_ba_runs - ba_before; }

  SyntheticScene scene{300, 7};
  Map map{0};
  LocalMapper mapper{map, scene.camera(), edgeOptions()};
  std::uint64_t next_id[5] = {0, 0, 0, 0, 0};
  std::size_t ba_before = 0;
};

TEST_F(LocalMapperClients, AnotherClientsWaitingKeyFrameDoesNotCutAKeyFramesMappingShort) {
  // Client 1's keyframe mapped while client 2's waits behind it: both get their local BA.
  mapper.insertKeyFrame(keyFrameOf(1, 20, 0.2));
  mapper.insertKeyFrame(keyFrameOf(2, 0, 1.0));
  mapper.processAll();
  EXPECT_EQ(mappedInFull(), 2u);
}

TEST_F(LocalMapperClients, ABacklogOfOtherClientsKeyFramesCutsItShort) {
  // Three others wait (LocalMapperOptions::max_queue): mapping in short keeps up with them.
  mapper.insertKeyFrame(keyFrameOf(1, 20, 0.2));
  for (std::uint8_t client = 2; client <= 4; ++client) {
    mapper.insertKeyFrame(keyFrameOf(client, 0, 1.0 * client));
  }
  mapper.processAll();
  // The first mapped with 3 keyframes behind it, in short; the others in full.
  EXPECT_EQ(mappedInFull(), 3u);
}

TEST_F(LocalMapperClients, AKeyFrameWhoseOwnClientSentTheNextIsMappedShort) {
  mapper.insertKeyFrame(keyFrameOf(1, 20, 0.2));
  mapper.insertKeyFrame(keyFrameOf(1, 30, 0.3));
  mapper.processAll();
  EXPECT_EQ(mappedInFull(), 1u);  // the last one only
}

}  // namespace
}  // namespace edgeslam
