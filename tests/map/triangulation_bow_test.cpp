// The bag-of-words new-point search on synthetic views (known correspondences), with direct
// indexes made by hand: which node a keypoint is filed under decides which pairs can be found.
#include <gtest/gtest.h>

#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include "map/map_matching.h"
#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

using test::poseAt;
using test::SyntheticScene;
using test::SyntheticView;

constexpr int kNodes = 20;

// Every keypoint filed under node (scene point + shift) mod kNodes: with the same shift in both
// views the true correspondences share a node, with different shifts they never do.
std::shared_ptr<KeyFramePlace> placeOf(const SyntheticView& view, int shift, int depth = 2) {
  std::vector<std::pair<NodeId, int>> pairs;
  for (std::size_t i = 0; i < view.scene_point.size(); ++i) {
    pairs.emplace_back(static_cast<NodeId>((view.scene_point[i] + shift) % kNodes),
                       static_cast<int>(i));
  }
  auto place = std::make_shared<KeyFramePlace>();
  place->features = FeatureVector::fromPairs(std::move(pairs));
  place->direct_index_depth = depth;
  return place;
}

class TriangulationByBow : public ::testing::Test {
 protected:
  TriangulationByBow()
      : scene_(600, 42),
        view1_(scene_.view(poseAt({0, 0, 0}), 8, false)),
        view2_(scene_.view(poseAt({0.15, 0.02, 0.05}, 0.03), 8, false)) {}

  int wrongPairs(const std::vector<std::pair<std::size_t, std::size_t>>& pairs) const {
    int wrong = 0;
    for (const auto& [i, j] : pairs) wrong += view1_.scene_point[i] != view2_.scene_point[j];
    return wrong;
  }

  SyntheticScene scene_;
  SyntheticView view1_, view2_;
  Map map_;
};

TEST_F(TriangulationByBow, FindsTheTrueCorrespondencesUnderSharedNodes) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, false);
  kf1->setPlace(placeOf(view1_, 0));
  kf2->setPlace(placeOf(view2_, 0));
  ASSERT_TRUE(canMatchForTriangulationByBow(*kf1, *kf2));

  const auto by_bow = matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true);
  const auto by_band = matchForTriangulation(*kf1, *kf2, scene_.camera(), true);
  EXPECT_GT(by_bow.size(), 0.7 * static_cast<double>(view2_.scene_point.size()));
  EXPECT_EQ(wrongPairs(by_bow), 0);
  // Fewer candidates per keypoint: the ratio test loses nothing that the band search keeps.
  EXPECT_GE(by_bow.size(), by_band.size());
  EXPECT_TRUE(std::is_sorted(by_bow.begin(), by_bow.end()));
}

TEST_F(TriangulationByBow, ComparesOnlyKeypointsUnderTheSameNode) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, false);
  kf1->setPlace(placeOf(view1_, 0));
  kf2->setPlace(placeOf(view2_, 1));  // no true pair shares a node
  // The random descriptors of different scene points are ~128 bits apart: nothing passes.
  EXPECT_TRUE(matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true).empty());
  EXPECT_FALSE(matchForTriangulation(*kf1, *kf2, scene_.camera(), true).empty());
}

TEST_F(TriangulationByBow, FallsBackToTheBandSearchWithoutComparableDirectIndexes) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, false);
  const auto by_band = matchForTriangulation(*kf1, *kf2, scene_.camera(), true);
  ASSERT_FALSE(by_band.empty());

  // Neither described, one described, described at different depths, by different vocabularies:
  // all the band search.
  EXPECT_FALSE(canMatchForTriangulationByBow(*kf1, *kf2));
  EXPECT_EQ(matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true), by_band);
  kf1->setPlace(placeOf(view1_, 1));
  EXPECT_FALSE(canMatchForTriangulationByBow(*kf1, *kf2));
  EXPECT_EQ(matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true), by_band);
  kf2->setPlace(placeOf(view2_, 0, 3));
  EXPECT_FALSE(canMatchForTriangulationByBow(*kf1, *kf2));
  EXPECT_EQ(matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true), by_band);
  auto other_vocabulary = placeOf(view2_, 0);
  const Vocabulary* const some_vocabulary = reinterpret_cast<const Vocabulary*>(this);
  other_vocabulary->vocabulary = some_vocabulary;
  kf2->setPlace(other_vocabulary);
  EXPECT_FALSE(canMatchForTriangulationByBow(*kf1, *kf2));
  EXPECT_EQ(matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true), by_band);
}

TEST_F(TriangulationByBow, SkipsKeypointsThatHaveAPoint) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, true);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, false);
  kf1->setPlace(placeOf(view1_, 0));
  kf2->setPlace(placeOf(view2_, 0));
  EXPECT_TRUE(matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true).empty());
  EXPECT_TRUE(matchForTriangulationByBow(*kf2, *kf1, scene_.camera(), true).empty());
}

TEST_F(TriangulationByBow, NoBaselineGivesNothing) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  const SyntheticView same_place = scene_.view(poseAt({0, 0, 0}, 0.05), 8, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, same_place, 1, false);
  kf1->setPlace(placeOf(view1_, 0));
  kf2->setPlace(placeOf(same_place, 0));
  EXPECT_TRUE(matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true).empty());
}

TEST_F(TriangulationByBow, ADirectIndexNamingMissingKeypointsIsAClearError) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, false);
  kf1->setPlace(placeOf(view1_, 0));
  auto bad = std::make_shared<KeyFramePlace>();
  bad->direct_index_depth = 2;
  std::vector<std::pair<NodeId, int>> pairs;
  for (int n = 0; n < kNodes; ++n) pairs.emplace_back(static_cast<NodeId>(n), 100000 + n);
  bad->features = FeatureVector::fromPairs(std::move(pairs));
  kf2->setPlace(bad);
  try {
    matchForTriangulationByBow(*kf1, *kf2, scene_.camera(), true);
    FAIL() << "expected std::invalid_argument";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("direct index"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace edgeslam
