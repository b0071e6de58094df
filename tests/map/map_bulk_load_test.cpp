// Map's bulk load (loadPoint, linkAllConnections) against the calls it stands for
// (createMapPoint, addObservation, setPointAppearance; updateConnections on each keyframe in id
// order), on a graph with the cases where the order of those calls shows: weak links (under 15
// shared points) dropped when the later keyframe keeps a stronger one, ties of weight and of
// strongest link, and a keypoint claimed by two points.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

#include "map/map.h"

namespace edgeslam {
namespace {

constexpr std::size_t kKeyFrames = 6;
constexpr std::size_t kKeypoints = 200;

// A point seen by `keyframes`, each at its next free keypoint.
struct PointPlan {
  std::vector<std::size_t> keyframes;
  std::vector<std::size_t> keypoints;
};

std::vector<PointPlan> plan() {
  // Groups of shared points: {keyframes}, count.
  const std::vector<std::pair<std::vector<std::size_t>, int>> groups = {
      {{0, 1}, 5},      // 0's only (weak) link; 1 keeps 2 and 3 instead
      {{1, 2}, 20},     //
      {{1, 3}, 20},     // a tie of weight for 1
      {{2, 3}, 20},     //
      {{2, 3, 4}, 16},  // three observers
      {{3, 4}, 15},     // exactly the threshold
      {{4, 5}, 3},      // 5's strongest link is a tie: 0 (lower id) wins
      {{0, 5}, 3},
  };
  std::array<std::size_t, kKeyFrames> next{};
  std::vector<PointPlan> out;
  for (const auto& [keyframes, count] : groups) {
    for (int i = 0; i < count; ++i) {
      PointPlan p{keyframes, {}};
      for (const std::size_t k : keyframes) p.keypoints.push_back(next[k]++);
      out.push_back(std::move(p));
    }
  }
  // A point that takes a keypoint of the first {0, 1} point in keyframe 1: that point, left with
  // one observation, is erased.
  out.push_back({{1, 2}, {out.front().keypoints[1], next[2]++}});
  return out;
}

std::vector<KeyFrame*> addKeyFrames(Map& map) REQUIRES(map.updateMutex()) {
  std::vector<KeyFrame*> out;
  for (std::size_t k = 0; k < kKeyFrames; ++k) {
    auto features = std::make_shared<FrameFeatures>();
    features->keypoints.resize(kKeypoints);
    features->descriptors = cv::Mat::zeros(static_cast<int>(kKeypoints), 32, CV_8U);
    features->depth.assign(kKeypoints, k % 2 == 0 ? 1.5f : 0.f);  // some with depth
    out.push_back(map.createKeyFrame(k, static_cast<double>(k), std::move(features), SE3d(),
                                     static_cast<KeyFrameId>(10 + k)));
  }
  return out;
}

std::array<std::uint8_t, 32> descriptorOf(std::size_t i) {
  std::array<std::uint8_t, 32> d{};
  for (std::size_t b = 0; b < d.size(); ++b) d[b] = static_cast<std::uint8_t>(i * 7 + b);
  return d;
}

void expectSameMaps(Map& a, Map& b) REQUIRES(a.updateMutex(), b.updateMutex()) {
  ASSERT_EQ(a.pointCount(), b.pointCount());
  const auto keyframes_a = a.keyFrames();
  const auto keyframes_b = b.keyFrames();
  ASSERT_EQ(keyframes_a.size(), keyframes_b.size());
  for (std::size_t k = 0; k < keyframes_a.size(); ++k) {
    const KeyFrame& ka = *keyframes_a[k];
    const KeyFrame& kb = *keyframes_b[k];
    for (std::size_t i = 0; i < ka.size(); ++i) {
      ASSERT_EQ(ka.point(i) != nullptr ? ka.point(i)->id() : kInvalidId,
                kb.point(i) != nullptr ? kb.point(i)->id() : kInvalidId);
    }
    std::vector<std::pair<KeyFrameId, int>> ordered_a, ordered_b;
    for (KeyFrame* kf : ka.bestCovisibles(100)) ordered_a.emplace_back(kf->id(), ka.weight(kf));
    for (KeyFrame* kf : kb.bestCovisibles(100)) ordered_b.emplace_back(kf->id(), kb.weight(kf));
    EXPECT_EQ(ordered_a, ordered_b) << "keyframe " << ka.id();
    EXPECT_EQ(ka.parent() != nullptr ? ka.parent()->id() : kInvalidId,
              kb.parent() != nullptr ? kb.parent()->id() : kInvalidId)
        << "keyframe " << ka.id();
    EXPECT_EQ(ka.children().size(), kb.children().size()) << "keyframe " << ka.id();
  }
  for (MapPoint* pa : a.mapPoints()) {
    const MapPoint* pb = b.mapPoint(pa->id());
    ASSERT_NE(pb, nullptr);
    EXPECT_EQ(pa->observationCount(), pb->observationCount());
    EXPECT_EQ(pa->observations().size(), pb->observations().size());
    EXPECT_EQ(pa->referenceKeyFrame()->id(), pb->referenceKeyFrame()->id());
    EXPECT_EQ(cv::norm(pa->descriptor(), pb->descriptor(), cv::NORM_HAMMING), 0.0);
    EXPECT_EQ(pa->normal(), pb->normal());
    EXPECT_EQ(pa->baseMaxDistance(), pb->baseMaxDistance());
  }
}

TEST(MapBulkLoad, LinksTheGraphUpdateConnectionsLinksKeyFrameByKeyFrame) {
  const std::vector<PointPlan> points = plan();
  Map one_by_one;
  Map bulk;
  MutexLock lock_a(one_by_one.updateMutex());
  MutexLock lock_b(bulk.updateMutex());
  one_by_one.setChangeRecording(false);
  bulk.setChangeRecording(false);
  const auto keyframes_a = addKeyFrames(one_by_one);
  const auto keyframes_b = addKeyFrames(bulk);
  bulk.reservePoints(points.size());
  std::vector<std::pair<KeyFrame*, std::size_t>> observers;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const PointPlan& p = points[i];
    const auto id = static_cast<MapPointId>(1000 + i);
    const Eigen::Vector3d position(0.1 * static_cast<double>(i), 1.0, 2.0);
    const Eigen::Vector3d normal(0.0, 0.0, 1.0);
    const auto descriptor = descriptorOf(i);
    MapPoint* point = one_by_one.createMapPoint(position, keyframes_a[p.keyframes[0]], id);
    observers.clear();
    for (std::size_t j = 0; j < p.keyframes.size(); ++j) {
      one_by_one.addObservation(point, keyframes_a[p.keyframes[j]], p.keypoints[j]);
      observers.emplace_back(keyframes_b[p.keyframes[j]], p.keypoints[j]);
    }
    const cv::Mat descriptor_mat(1, 32, CV_8U, const_cast<std::uint8_t*>(descriptor.data()));
    one_by_one.setPointAppearance(point, normal, descriptor_mat, 0.5f, 3.0f);
    bulk.loadPoint({.id = id,
                    .position = position,
                    .reference = keyframes_b[p.keyframes[0]],
                    .observers = observers,
                    .normal = normal,
                    .descriptor = descriptor.data(),
                    .min_distance = 0.5f,
                    .max_distance = 3.0f});
  }
  for (KeyFrame* keyframe : one_by_one.keyFrames()) one_by_one.updateConnections(keyframe);
  bulk.linkAllConnections();
  EXPECT_TRUE(bulk.changes().empty());

  // The cases are there: the stolen keypoint's point erased; 0's weak link to 1 dropped (1 keeps
  // stronger ones), kept to 5 (whose tie of 3 and 3 goes to 0).
  EXPECT_EQ(one_by_one.pointCount(), points.size() - 1);
  EXPECT_EQ(keyframes_a[0]->weight(keyframes_a[1]), 0);
  EXPECT_EQ(keyframes_a[0]->weight(keyframes_a[5]), 3);
  EXPECT_EQ(keyframes_a[5]->weight(keyframes_a[4]), 0);
  EXPECT_EQ(keyframes_a[5]->parent(), keyframes_a[0]);
  expectSameMaps(one_by_one, bulk);
}

// Keyframes, then every planned point but the last, one call at a time.
void addPlannedPoints(Map& map, const std::vector<PointPlan>& points) REQUIRES(map.updateMutex()) {
  const auto keyframes = addKeyFrames(map);
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    const PointPlan& p = points[i];
    MapPoint* point = map.createMapPoint(Eigen::Vector3d(0, 0, 1), keyframes[p.keyframes[0]],
                                         static_cast<MapPointId>(1000 + i));
    for (std::size_t j = 0; j < p.keyframes.size(); ++j) {
      map.addObservation(point, keyframes[p.keyframes[j]], p.keypoints[j]);
    }
  }
}

TEST(MapBulkLoad, UpdatesLinksThatAreThereAlready) {
  const std::vector<PointPlan> points = plan();
  Map once;
  Map twice;
  MutexLock lock_a(once.updateMutex());
  MutexLock lock_b(twice.updateMutex());
  addPlannedPoints(once, points);
  addPlannedPoints(twice, points);
  for (KeyFrame* keyframe : once.keyFrames()) once.updateConnections(keyframe);
  for (KeyFrame* keyframe : once.keyFrames()) once.updateConnections(keyframe);
  twice.linkAllConnections();
  twice.linkAllConnections();  // links there: updated keyframe by keyframe
  expectSameMaps(once, twice);
}

}  // namespace
}  // namespace edgeslam
