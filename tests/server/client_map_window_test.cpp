// The edge's choice of the part of the global map a bounded client holds: the neighbourhood
// around the client's latest keyframe, hysteresis on eviction, keyframes and points sent back on a
// revisit, and point records filtered to what the client can attach.
#include "server/client_map_window.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <set>

#include "mapping/corridor_map.h"

namespace edgeslam {
namespace {

using ::testing::ElementsAre;
using ::testing::IsEmpty;

std::vector<int> indices(const test::Corridor& c, const std::vector<KeyFrame*>& kfs) {
  std::vector<int> out;
  for (KeyFrame* kf : kfs) {
    for (std::size_t k = 0; k < c.keyframes.size(); ++k) {
      if (c.keyframes[k] == kf) out.push_back(static_cast<int>(k));
    }
  }
  return out;
}

std::vector<int> indices(const test::Corridor& c, const std::vector<KeyFrameId>& ids) {
  std::vector<int> out;
  for (KeyFrameId id : ids) {
    for (std::size_t k = 0; k < c.keyframes.size(); ++k) {
      if (c.keyframes[k]->id() == id) out.push_back(static_cast<int>(k));
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::set<int> heldIndices(const test::Corridor& c, const ClientMapWindow& window) {
  std::set<int> out;
  for (std::size_t k = 0; k < c.keyframes.size(); ++k) {
    if (window.holds(c.keyframes[k]->id())) out.insert(static_cast<int>(k));
  }
  return out;
}

std::set<int> range(int first, int last) {
  std::set<int> out;
  for (int k = first; k <= last; ++k) out.insert(k);
  return out;
}

TEST(KeyFrameNeighbourhood, BreadthFirstFromTheCentreStrongestLinksFirst) {
  test::Corridor c(20);
  MutexLock lock(c.map.updateMutex());
  // kf 10 links to 9 and 11 (30 shared points), 8 and 12 (20); 9 then adds 7.
  const auto six = keyFrameNeighbourhood(c.map, c.keyframes[10], 6, 0);
  EXPECT_THAT(indices(c, six), ElementsAre(10, 9, 11, 8, 12, 7));
  // A shorter neighbourhood is a prefix of a longer one (the window inside the keep window).
  const auto nine = keyFrameNeighbourhood(c.map, c.keyframes[10], 9, 0);
  ASSERT_EQ(nine.size(), 9u);
  EXPECT_TRUE(std::equal(six.begin(), six.end(), nine.begin()));
  // The whole connected map when asked for more.
  EXPECT_EQ(keyFrameNeighbourhood(c.map, c.keyframes[10], 100, 0).size(), 20u);
  EXPECT_THAT(keyFrameNeighbourhood(c.map, nullptr, 6, 0), IsEmpty());
}

TEST(KeyFrameNeighbourhood, TheMostRecentKeyFramesComeWithTheCentre) {
  test::Corridor c(20);
  MutexLock lock(c.map.updateMutex());
  const auto chosen = keyFrameNeighbourhood(c.map, c.keyframes[5], 6, 2);
  EXPECT_THAT(indices(c, chosen), ElementsAre(5, 19, 18, 4, 6, 3));
}

class ClientMapWindowTest : public ::testing::Test {
 protected:
  ClientMapWindowTest() : window_(options()) {
    for (KeyFrame* kf : c_.keyframes) window_.clientHolds(kf->id());
  }
  static ClientMapWindowOptions options() {
    ClientMapWindowOptions o;
    o.keyframes = 6;
    o.keep_factor = 1.5;  // keep window of 9
    o.recent_share = 0.0;
    return o;
  }
  MapSlice shapeAround(int centre) REQUIRES(c_.map.updateMutex()) {
    MapSlice slice;
    window_.shape(c_.map, c_.keyframes[static_cast<std::size_t>(centre)], slice);
    return slice;
  }

  test::Corridor c_{30};
  ClientMapWindow window_;
};

TEST_F(ClientMapWindowTest, EvictsWhatLeavesTheLargerWindowOnly) {
  MutexLock lock(c_.map.updateMutex());
  EXPECT_EQ(window_.keepSize(), 9u);
  MapSlice slice = shapeAround(29);
  // Keep window around the newest keyframe 29: 21..29; everything older is evicted, nothing sent.
  EXPECT_EQ(
      indices(c_, slice.keyframes_evicted),
      std::vector<int>({0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20}));
  EXPECT_THAT(slice.keyframes, IsEmpty());
  EXPECT_EQ(heldIndices(c_, window_), range(21, 29));

  // The walk goes on: the window around 30 is 25..30, the keep window 22..30; only 21 leaves, and
  // 22..24 stay although outside the window (hysteresis).
  window_.clientHolds(c_.addKeyFrame(300)->id());
  slice = shapeAround(30);
  EXPECT_EQ(indices(c_, slice.keyframes_evicted), std::vector<int>({21}));
  EXPECT_THAT(slice.keyframes, IsEmpty());
  EXPECT_EQ(heldIndices(c_, window_), range(22, 30));
}

TEST_F(ClientMapWindowTest, RevisitSendsKeyFramesAndOnlyThePointsTheClientLacks) {
  MutexLock lock(c_.map.updateMutex());
  shapeAround(29);
  window_.clientHolds(c_.addKeyFrame(300)->id());
  shapeAround(30);  // holds 22..30
  // Back where keyframe 20 was: the new keyframe 31 sees its points.
  window_.clientHolds(c_.addKeyFrame(200)->id());
  const MapSlice slice = shapeAround(31);
  // Keep window around 31: 31 and 16..23, so 24..30 go; the window (31, 18..22) comes back.
  EXPECT_EQ(indices(c_, slice.keyframes_evicted), std::vector<int>({24, 25, 26, 27, 28, 29, 30}));
  std::vector<KeyFrameId> sent;
  for (const KeyFrameRecord& r : slice.keyframes) sent.push_back(r.id);
  EXPECT_EQ(sent, std::vector<KeyFrameId>({c_.id(20), c_.id(19), c_.id(21), c_.id(18)}));
  for (const KeyFrameRecord& r : slice.keyframes) {
    EXPECT_EQ(r.features.keypoints.size(), static_cast<std::size_t>(test::Corridor::kSpan));
  }
  // Keyframes 18..21 see points 180..249; the client still holds 22, 23 and 31, which see
  // 200..269: only 180..199 are sent.
  std::set<MapPointId> expected;
  for (int i = 180; i < 200; ++i) expected.insert(c_.point(i)->id());
  std::set<MapPointId> points;
  for (const MapPointRecord& r : slice.points_upserted) points.insert(r.id);
  EXPECT_EQ(points, expected);
  std::set<int> held = range(18, 23);
  held.insert(31);
  EXPECT_EQ(heldIndices(c_, window_), held);
}

TEST_F(ClientMapWindowTest, AtMostSoManyKeyFramesComeBackPerSlice) {
  MutexLock lock(c_.map.updateMutex());
  ClientMapWindowOptions o = options();
  o.max_entering_per_slice = 2;
  window_ = ClientMapWindow(o);
  for (int k = 21; k < 30; ++k) window_.clientHolds(c_.id(k));
  MapSlice slice = shapeAround(10);
  ASSERT_EQ(slice.keyframes.size(), 2u);
  EXPECT_EQ(slice.keyframes[0].id, c_.id(10));  // the closest first
  EXPECT_EQ(slice.keyframes[1].id, c_.id(9));
  slice = shapeAround(10);
  ASSERT_EQ(slice.keyframes.size(), 2u);
  EXPECT_EQ(slice.keyframes[0].id, c_.id(11));
}

TEST_F(ClientMapWindowTest, NewerKeyFramesThanTheCentreStay) {
  MutexLock lock(c_.map.updateMutex());
  // The client's newest keyframes may still be queued for mapping: never evicted.
  const MapSlice slice = shapeAround(5);
  const std::vector<int> evicted = indices(c_, slice.keyframes_evicted);
  EXPECT_TRUE(std::none_of(evicted.begin(), evicted.end(), [](int k) { return k > 5; }));
  EXPECT_EQ(heldIndices(c_, window_), range(1, 29));
}

TEST_F(ClientMapWindowTest, PointRecordsOnlyForPointsAHeldKeyFrameSees) {
  MutexLock lock(c_.map.updateMutex());
  shapeAround(29);  // holds 21..29: points 210..329
  MapSlice slice;
  for (int i : {5, 205, 215, 320}) slice.points_upserted.push_back(mapPointRecord(*c_.point(i)));
  for (int i : {6, 250}) slice.point_positions.push_back({c_.point(i)->id(), {1, 2, 3}});
  slice.point_positions.push_back({987654321, {1, 2, 3}});  // unknown on the edge
  window_.shape(c_.map, nullptr, slice);
  std::vector<MapPointId> upserted;
  for (const MapPointRecord& r : slice.points_upserted) upserted.push_back(r.id);
  EXPECT_THAT(upserted, ElementsAre(c_.point(215)->id(), c_.point(320)->id()));
  ASSERT_EQ(slice.point_positions.size(), 1u);
  EXPECT_EQ(slice.point_positions[0].id, c_.point(250)->id());
}

TEST_F(ClientMapWindowTest, ErasedKeyFramesAreNoLongerHeldNorEvicted) {
  MutexLock lock(c_.map.updateMutex());
  MapSlice slice;
  slice.keyframes_erased = {c_.id(3)};
  c_.map.eraseKeyFrame(c_.keyframes[3]);
  window_.shape(c_.map, c_.keyframes[29], slice);
  EXPECT_FALSE(window_.holds(c_.id(3)));
  const std::vector<int> evicted = indices(c_, slice.keyframes_evicted);
  EXPECT_EQ(std::count(evicted.begin(), evicted.end(), 3), 0);
  EXPECT_EQ(std::count(evicted.begin(), evicted.end(), 4), 1);
}

TEST(ClientMapWindow, UnboundedLeavesTheSliceAlone) {
  test::Corridor c(10);
  MutexLock lock(c.map.updateMutex());
  ClientMapWindow window;
  EXPECT_FALSE(window.bounded());
  MapSlice slice;
  slice.points_upserted.push_back(mapPointRecord(*c.point(0)));
  window.shape(c.map, c.keyframes[9], slice);
  EXPECT_THAT(slice.keyframes_evicted, IsEmpty());
  EXPECT_EQ(slice.points_upserted.size(), 1u);
}

}  // namespace
}  // namespace edgeslam
