// Local mapping with a vocabulary: keyframes are described once (bag of words and direct index,
// kept on the KeyFrame for loop detection) before triangulation searches through the direct index;
// the band search stays available as an option and as the path without a vocabulary.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "map/synthetic_views.h"
#include "mapping/local_mapper.h"
#include "mapping/loop_detector.h"
#include "place/vocabulary_training.h"

namespace edgeslam {
namespace {

using test::poseAt;
using test::SyntheticScene;
using test::SyntheticView;

// Trained on the scene's own (perturbed) descriptors: a view's keypoint and its true
// correspondence mostly descend to the same depth-2 node.
std::shared_ptr<const Vocabulary> vocabularyFor(const std::vector<SyntheticView>& views) {
  std::vector<cv::Mat> descriptors;
  for (const SyntheticView& view : views) descriptors.push_back(view.features->descriptors);
  VocabularyTrainingOptions options;
  options.branching = 6;
  options.levels = 3;
  return std::make_shared<const Vocabulary>(trainVocabulary(descriptors, options));
}

class LocalMapperBow : public ::testing::Test {
 protected:
  LocalMapperBow()
      : scene_(600, 7),
        view1_(scene_.view(poseAt({0, 0, 0}), 8, false)),
        view2_(scene_.view(poseAt({0.15, 0.02, 0.05}, 0.03), 8, false)),
        vocabulary_(vocabularyFor({view1_, view2_})) {}

  // kf1 and kf2 share the points of the even scene points; the odd ones are left to triangulate.
  void makeKeyFrames() {
    MutexLock lock(map_.updateMutex());
    kf1_ = scene_.addKeyFrame(map_, view1_, 0, false);
    kf2_ = scene_.addKeyFrame(map_, view2_, 1, false);
    for (std::size_t i = 0; i < view1_.scene_point.size(); ++i) {
      const int s = view1_.scene_point[i];
      if (s % 2 != 0) continue;
      const auto it = std::find(view2_.scene_point.begin(), view2_.scene_point.end(), s);
      if (it == view2_.scene_point.end()) continue;
      MapPoint* p = map_.createMapPoint(scene_.points()[static_cast<std::size_t>(s)], kf1_);
      map_.addObservation(p, kf1_, i);
      map_.addObservation(p, kf2_, static_cast<std::size_t>(it - view2_.scene_point.begin()));
      map_.refreshPoint(p);
    }
    map_.updateConnections(kf1_);
  }

  std::size_t pointCount() const {
    MutexLock lock(map_.updateMutex());
    return map_.pointCount();
  }

  LocalMapperStats mapSecondKeyFrame(const LocalMapperOptions& options) {
    LocalMapper mapper(map_, scene_.camera(), options);
    mapper.insertKeyFrame(kf2_);
    mapper.processAll();
    return mapper.stats();
  }

  static LocalMapperOptions options(TriangulationSearch search,
                                    std::shared_ptr<const Vocabulary> vocabulary) {
    LocalMapperOptions o;
    o.monocular = true;
    o.run_local_ba = false;
    o.cull_keyframes = false;
    o.triangulation_search = search;
    o.vocabulary = std::move(vocabulary);
    return o;
  }

  SyntheticScene scene_;
  SyntheticView view1_, view2_;
  std::shared_ptr<const Vocabulary> vocabulary_;
  Map map_;
  KeyFrame* kf1_ = nullptr;
  KeyFrame* kf2_ = nullptr;
};

TEST_F(LocalMapperBow, DescribesKeyFramesAndTriangulatesThroughTheDirectIndex) {
  makeKeyFrames();
  const std::size_t points_before = pointCount();
  const LocalMapperStats stats =
      mapSecondKeyFrame(options(TriangulationSearch::kBagOfWords, vocabulary_));

  ASSERT_NE(kf2_->place(), nullptr);
  ASSERT_NE(kf1_->place(), nullptr);  // the neighbour, described when it was needed
  EXPECT_EQ(kf2_->place()->vocabulary, vocabulary_.get());
  EXPECT_EQ(kf2_->place()->direct_index_depth, 2);
  EXPECT_EQ(kf2_->place()->features.featureCount(), kf2_->size());
  EXPECT_FALSE(kf2_->place()->bow.empty());

  EXPECT_GE(stats.triangulation_searches, 1u);
  EXPECT_EQ(stats.triangulation_bow_searches, stats.triangulation_searches);
  EXPECT_GT(stats.triangulation_pairs, 100u);
  // About half of the scene points seen by both keyframes had no point yet.
  EXPECT_GT(stats.points_created, 100u);
  EXPECT_GT(pointCount(), points_before + 100);

  // Loop detection takes the description the mapper made.
  LoopDetector detector(vocabulary_);
  const KeyFrameBow& bow = detector.describe(*kf2_);
  EXPECT_EQ(bow.features, kf2_->place()->features);
  EXPECT_EQ(bow.bow, kf2_->place()->bow);
}

TEST_F(LocalMapperBow, BandSearchOnRequestOrWithoutAVocabulary) {
  for (const auto& [search, vocabulary] :
       {std::pair{TriangulationSearch::kEpipolarBand, vocabulary_},
        std::pair{TriangulationSearch::kBagOfWords, std::shared_ptr<const Vocabulary>()}}) {
    {
      MutexLock lock(map_.updateMutex());
      map_.clear();
    }
    makeKeyFrames();
    const LocalMapperStats stats = mapSecondKeyFrame(options(search, vocabulary));
    EXPECT_EQ(kf2_->place(), nullptr);
    EXPECT_GE(stats.triangulation_searches, 1u);
    EXPECT_EQ(stats.triangulation_bow_searches, 0u);
    EXPECT_GT(stats.points_created, 100u);
  }
}

TEST(TriangulationSearchNames, RoundTrip) {
  for (const TriangulationSearch s :
       {TriangulationSearch::kBagOfWords, TriangulationSearch::kEpipolarBand}) {
    EXPECT_EQ(parseTriangulationSearch(toString(s)), s);
  }
  EXPECT_EQ(parseTriangulationSearch("brute"), std::nullopt);
}

}  // namespace
}  // namespace edgeslam
