// Matching two images through their direct indexes, on synthetic descriptors.
#include "place/bow_matching.h"

#include <gtest/gtest.h>

#include <numeric>
#include <random>

#include "place/vocabulary_training.h"
#include "synthetic_descriptors.h"

namespace edgeslam {
namespace {

class BowMatching : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::mt19937 rng(8);
    prototypes_ = new cv::Mat(test::randomDescriptors(400, rng));
    std::vector<cv::Mat> training;
    for (int i = 0; i < 20; ++i) {
      std::vector<int> rows(400);
      std::iota(rows.begin(), rows.end(), 0);
      training.push_back(test::imageOf(*prototypes_, rows, 6, rng));
    }
    VocabularyTrainingOptions o;
    o.branching = 6;
    o.levels = 3;
    vocabulary_ = new Vocabulary(trainVocabulary(training, o));
  }
  static void TearDownTestSuite() {
    delete prototypes_;
    delete vocabulary_;
  }
  static cv::Mat* prototypes_;
  static Vocabulary* vocabulary_;
};

cv::Mat* BowMatching::prototypes_ = nullptr;
Vocabulary* BowMatching::vocabulary_ = nullptr;

TEST_F(BowMatching, RecoversAShuffledNoisyCopy) {
  std::mt19937 rng(9);
  std::vector<int> rows_a(300), rows_b(300);
  std::iota(rows_a.begin(), rows_a.end(), 0);
  rows_b = rows_a;
  std::shuffle(rows_b.begin(), rows_b.end(), rng);
  const cv::Mat a = test::imageOf(*prototypes_, rows_a, 6, rng);
  const cv::Mat b = test::imageOf(*prototypes_, rows_b, 6, rng);
  BowVector bow_a, bow_b;
  FeatureVector fa, fb;
  vocabulary_->transform(a, 1, bow_a, fa);
  vocabulary_->transform(b, 1, bow_b, fb);
  const auto matches = matchByBow(fa, a, fb, b);
  EXPECT_GT(matches.size(), 240U);
  std::vector<bool> used_b(300, false);
  int correct = 0;
  for (const cv::DMatch& m : matches) {
    EXPECT_FALSE(used_b[m.trainIdx]) << "B feature matched twice";
    used_b[m.trainIdx] = true;
    EXPECT_LE(m.distance, 50.0F);
    correct += rows_a[m.queryIdx] == rows_b[m.trainIdx] ? 1 : 0;
  }
  EXPECT_EQ(correct, static_cast<int>(matches.size()));
  EXPECT_TRUE(std::is_sorted(matches.begin(), matches.end(),
                             [](const auto& x, const auto& y) { return x.queryIdx < y.queryIdx; }));
}

TEST_F(BowMatching, RatioTestAndOneToOneDropAmbiguousFeatures) {
  std::mt19937 rng(10);
  // B holds two identical copies of each prototype: every best match ties with its second best.
  const cv::Mat a = test::imageOf(*prototypes_, {0, 1, 2, 3}, 0, rng);
  const cv::Mat b = test::imageOf(*prototypes_, {0, 0, 1, 1, 2, 2, 3, 3}, 0, rng);
  BowVector bow;
  FeatureVector fa, fb;
  vocabulary_->transform(a, 0, bow, fa);
  vocabulary_->transform(b, 0, bow, fb);
  EXPECT_TRUE(matchByBow(fa, a, fb, b).empty());
  // Without the ratio test each prototype matches once, and A repeated twice still matches once.
  const cv::Mat a2 = test::imageOf(*prototypes_, {0, 0, 1, 1}, 0, rng);
  const cv::Mat b2 = test::imageOf(*prototypes_, {0, 1}, 0, rng);
  FeatureVector fa2, fb2;
  vocabulary_->transform(a2, 0, bow, fa2);
  vocabulary_->transform(b2, 0, bow, fb2);
  const auto matches = matchByBow(fa2, a2, fb2, b2, {50, 1.0});
  ASSERT_EQ(matches.size(), 2U);
  EXPECT_EQ(matches[0].queryIdx, 0);  // the lower A index wins a tie
  EXPECT_EQ(matches[1].queryIdx, 2);
}

TEST_F(BowMatching, DistanceThresholdAndBadInput) {
  std::mt19937 rng(11);
  const cv::Mat a = test::imageOf(*prototypes_, {5, 6, 7}, 0, rng);
  const cv::Mat b = test::imageOf(*prototypes_, {5, 6, 7}, 40, rng);
  BowVector bow;
  FeatureVector fa, fb;
  vocabulary_->transform(a, 3, bow, fa);  // everything under the root
  vocabulary_->transform(b, 3, bow, fb);
  EXPECT_EQ(matchByBow(fa, a, fb, b, {50, 1.0}).size(), 3U);
  EXPECT_TRUE(matchByBow(fa, a, fb, b, {39, 1.0}).empty());
  EXPECT_THROW(matchByBow(fa, a.rowRange(0, 2), fb, b), std::invalid_argument);
  EXPECT_THROW(matchByBow(fa, cv::Mat(3, 32, CV_32F), fb, b), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
