// A real edge map read back from its store: loadStoredSession must rebuild exactly the map the
// straightforward load builds (each point upserted, each keyframe's connections updated in id
// order), and its covisibility graph must be the one the stored observations define.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <map>
#include <set>
#include <utility>
#include <vector>

#include "map/map_replication.h"
#include "store/map_store.h"
#include "store/stored_map_loader.h"
#include "support/edgeslam_command.h"
#include "support/fresh_temp_dir.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr const char* kSequence = "datasets/7scenes-redkitchen-1000";

// The load as it was written first: every record through the replication functions.
void loadOneByOne(const StoredSession& session, Map& map) {
  MutexLock lock(map.updateMutex());
  map.setChangeRecording(false);
  KeyFrameId newest = kInvalidId;
  for (const KeyFrameRecord& record : session.keyframes) {
    map.createKeyFrame(record.frame_index, record.timestamp,
                       featuresFromRecord(record.features, session.info.camera), record.T_cw,
                       record.id);
    newest = std::max(newest, record.id);
  }
  for (const MapPointRecord& record : session.points) {
    upsertPointRecord(map, record, newest);
    map.ids().advancePast(record.id);
  }
  for (KeyFrame* keyframe : map.keyFrames()) map.updateConnections(keyframe);
  map.setChangeRecording(true);
}

std::vector<std::pair<KeyFrameId, int>> orderedConnections(const KeyFrame& keyframe) {
  std::vector<std::pair<KeyFrameId, int>> out;
  for (KeyFrame* kf : keyframe.bestCovisibles(keyframe.connections().size())) {
    out.emplace_back(kf->id(), keyframe.weight(kf));
  }
  return out;
}

KeyFrameId idOf(const KeyFrame* keyframe) {
  return keyframe != nullptr ? keyframe->id() : kInvalidId;
}

void expectSameMap(Map& a, Map& b) REQUIRES(a.updateMutex(), b.updateMutex()) {
  ASSERT_EQ(a.keyFrameCount(), b.keyFrameCount());
  ASSERT_EQ(a.pointCount(), b.pointCount());
  EXPECT_TRUE(b.changes().empty());
  const auto keyframes_a = a.keyFrames();
  const auto keyframes_b = b.keyFrames();
  for (std::size_t i = 0; i < keyframes_a.size(); ++i) {
    const KeyFrame& ka = *keyframes_a[i];
    const KeyFrame& kb = *keyframes_b[i];
    ASSERT_EQ(ka.id(), kb.id());
    EXPECT_EQ(ka.frameIndex(), kb.frameIndex());
    EXPECT_EQ(ka.timestamp(), kb.timestamp());
    EXPECT_EQ(ka.pose().translation(), kb.pose().translation());
    EXPECT_EQ(ka.pose().rotation().coeffs(), kb.pose().rotation().coeffs());
    ASSERT_EQ(ka.size(), kb.size());
    EXPECT_EQ(cv::norm(ka.features().descriptors, kb.features().descriptors, cv::NORM_HAMMING),
              0.0);
    for (std::size_t j = 0; j < ka.size(); ++j) {
      const MapPoint* pa = ka.point(j);
      const MapPoint* pb = kb.point(j);
      ASSERT_EQ(pa != nullptr ? pa->id() : kInvalidId, pb != nullptr ? pb->id() : kInvalidId)
          << "keyframe " << ka.id() << " keypoint " << j;
    }
    EXPECT_EQ(orderedConnections(ka), orderedConnections(kb)) << "keyframe " << ka.id();
    EXPECT_EQ(idOf(ka.parent()), idOf(kb.parent())) << "keyframe " << ka.id();
    std::vector<KeyFrameId> children_a, children_b;
    for (const KeyFrame* c : ka.children()) children_a.push_back(c->id());
    for (const KeyFrame* c : kb.children()) children_b.push_back(c->id());
    EXPECT_EQ(children_a, children_b) << "keyframe " << ka.id();
  }
  const auto points_a = a.mapPoints();
  const auto points_b = b.mapPoints();
  for (std::size_t i = 0; i < points_a.size(); ++i) {
    const MapPoint& pa = *points_a[i];
    const MapPoint& pb = *points_b[i];
    ASSERT_EQ(pa.id(), pb.id());
    EXPECT_EQ(pa.position(), pb.position());
    EXPECT_EQ(pa.normal(), pb.normal());
    EXPECT_EQ(cv::norm(pa.descriptor(), pb.descriptor(), cv::NORM_HAMMING), 0.0);
    EXPECT_EQ(pa.baseMinDistance(), pb.baseMinDistance());
    EXPECT_EQ(pa.baseMaxDistance(), pb.baseMaxDistance());
    EXPECT_EQ(idOf(pa.referenceKeyFrame()), idOf(pb.referenceKeyFrame()));
    EXPECT_EQ(pa.firstKeyFrameId(), pb.firstKeyFrameId());
    EXPECT_EQ(pa.observationCount(), pb.observationCount());
    ASSERT_EQ(pa.observations().size(), pb.observations().size());
    for (auto oa = pa.observations().begin(), ob = pb.observations().begin();
         oa != pa.observations().end(); ++oa, ++ob) {
      EXPECT_EQ(oa->first, ob->first);
      EXPECT_EQ(oa->second.index, ob->second.index);
    }
  }
  EXPECT_EQ(a.ids().next(), b.ids().next());  // the next id each would give
}

// The covisibility graph from the stored observations alone: a pair of keyframes is linked when
// they share at least 15 points, or when the newer one shares fewer than 15 with every keyframe
// and the most with the older one (its first, by id, of the most); strongest links first, ties by
// id; a keyframe's parent is the keyframe it shares the most points with, when that one is older.
void expectCovisibilityOfTheObservations(const StoredSession& session, const Map& map)
    REQUIRES(map.updateMutex()) {
  std::map<std::pair<KeyFrameId, KeyFrameId>, int> shared;
  for (const MapPointRecord& p : session.points) {
    std::set<KeyFrameId> observers;
    for (const PointObservationRecord& o : p.observations) observers.insert(o.keyframe);
    for (const KeyFrameId a : observers) {
      for (const KeyFrameId b : observers) {
        if (a != b) ++shared[{a, b}];
      }
    }
  }
  std::map<KeyFrameId, std::map<KeyFrameId, int>> weights;  // of each keyframe, by other
  for (const auto& [pair, w] : shared) weights[pair.first][pair.second] = w;
  const auto strongest = [&](KeyFrameId id) {
    std::pair<KeyFrameId, int> best{kInvalidId, 0};
    for (const auto& [other, w] : weights[id]) {
      if (w > best.second) best = {other, w};
    }
    return best;
  };
  const auto has_strong = [&](KeyFrameId id) {
    return std::any_of(weights[id].begin(), weights[id].end(),
                       [](const auto& e) { return e.second >= 15; });
  };
  std::size_t links = 0;
  for (const KeyFrameRecord& k : session.keyframes) {
    std::vector<std::pair<KeyFrameId, int>> expected;
    for (const auto& [other, w] : weights[k.id]) {
      const KeyFrameId newer = std::max(k.id, other);
      const KeyFrameId older = std::min(k.id, other);
      if (w >= 15 || (!has_strong(newer) && strongest(newer).first == older)) {
        expected.emplace_back(other, w);
      }
    }
    std::stable_sort(expected.begin(), expected.end(),
                     [](const auto& a, const auto& b) { return a.second > b.second; });
    const KeyFrame* keyframe = map.keyFrame(k.id);
    ASSERT_NE(keyframe, nullptr);
    EXPECT_EQ(orderedConnections(*keyframe), expected) << "keyframe " << k.id;
    const KeyFrameId parent = strongest(k.id).first;
    EXPECT_EQ(idOf(keyframe->parent()), parent < k.id ? parent : kInvalidId);
    links += expected.size();
  }
  EXPECT_GT(links, 4 * session.keyframes.size());
}

TEST(StoredMapLoad, RebuildsTheMapOfARealEdgeRunAsOneRecordAtATime) {
  EDGESLAM_REQUIRE_SHARED(kSequence);
  const auto store = test::freshTempDir("stored_map_load_store");
  const auto out = test::freshTempDir("stored_map_load_out");
  const auto run = test::runEdgeslam(
      "run --dataset " + test::sharedPath(kSequence).string() +
      " --mode edge --sensor rgbd --max-frames 200 --vocab none --fmin 0 --beta 1.0 --maps " +
      store.string() + " --map kitchen --out " + out.string());
  ASSERT_EQ(run.exit_code, 0) << run.output;
  const auto stored = openMapStore(store, MapStoreAccess::kRead)->loadMap("kitchen");
  ASSERT_TRUE(stored);
  ASSERT_EQ(stored->sessions.size(), 1u);
  const StoredSession& session = stored->sessions.front();
  ASSERT_GE(session.keyframes.size(), 10u);
  ASSERT_GE(session.points.size(), 1000u);

  Map one_by_one;
  loadOneByOne(session, one_by_one);
  Map loaded;
  loadStoredSession(session, loaded);
  {
    MutexLock lock_a(one_by_one.updateMutex());
    MutexLock lock_b(loaded.updateMutex());
    expectSameMap(one_by_one, loaded);
  }
  // (expectSameMap draws an id from each map: a fresh reference for the second comparison.)
  Map one_by_one_again;
  loadOneByOne(session, one_by_one_again);
  // Read again: its records own their arrays, which the map takes (as `map info --load` does).
  auto stored_again = openMapStore(store, MapStoreAccess::kRead)->loadMap("kitchen");
  ASSERT_TRUE(stored_again);
  StoredSession& taken = stored_again->sessions.front();
  Map loaded_taking_features;
  loadStoredSessionTakingFeatures(taken, loaded_taking_features);
  {
    MutexLock lock_a(one_by_one_again.updateMutex());
    MutexLock lock_b(loaded_taking_features.updateMutex());
    expectSameMap(one_by_one_again, loaded_taking_features);
  }
  EXPECT_TRUE(taken.keyframes.front().features.keypoints.empty());
  EXPECT_EQ(taken.keyframes.front().id, session.keyframes.front().id);
  {
    MutexLock lock(loaded.updateMutex());
    expectCovisibilityOfTheObservations(session, loaded);
  }
  std::filesystem::remove_all(store);
  std::filesystem::remove_all(out);
}

}  // namespace
}  // namespace edgeslam
