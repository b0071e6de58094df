// Vocabulary training, transform and scoring on synthetic descriptors.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <set>

#include "place/parallel_for.h"
#include "place/vocabulary_training.h"
#include "synthetic_descriptors.h"

namespace edgeslam {
namespace {

VocabularyTrainingOptions smallOptions(int threads = 1, std::uint64_t seed = 7) {
  VocabularyTrainingOptions o;
  o.branching = 4;
  o.levels = 3;
  o.threads = threads;
  o.seed = seed;
  return o;
}

const test::SyntheticScenes& scenes() {
  static const test::SyntheticScenes s = test::makeScenes(8, 40, 48, 60, 8, 11);
  return s;
}

TEST(BowVector, MakeMergesRepeatedWordsAndSorts) {
  const BowVector bow = makeBowVector({{5, 1.0}, {2, 0.5}, {5, 2.0}, {9, 0.0}});
  ASSERT_EQ(bow.size(), 2U);
  EXPECT_EQ(bow.entries[0], (BowEntry{2, 0.5}));
  EXPECT_EQ(bow.entries[1], (BowEntry{5, 3.0}));
  EXPECT_DOUBLE_EQ(bow.weightOf(5), 3.0);
  EXPECT_DOUBLE_EQ(bow.weightOf(4), 0.0);
}

TEST(BowVector, L1ScoreIsOneForSameZeroForDisjointAndSymmetric) {
  BowVector a = makeBowVector({{1, 0.5}, {2, 0.25}, {3, 0.25}});
  BowVector b = makeBowVector({{2, 0.5}, {4, 0.5}});
  const BowVector c = makeBowVector({{7, 1.0}});
  EXPECT_DOUBLE_EQ(l1Score(a, a), 1.0);
  EXPECT_DOUBLE_EQ(l1Score(a, c), 0.0);
  // |a-b|_1 = 0.5 + 0.25 + 0.25 + 0.5 = 1.5 -> 1 - 0.75
  EXPECT_NEAR(l1Score(a, b), 0.25, 1e-12);
  EXPECT_DOUBLE_EQ(l1Score(a, b), l1Score(b, a));
  EXPECT_EQ(sharedWordCount(a, b), 1);
  BowVector unnormalised = makeBowVector({{1, 2.0}, {2, 6.0}});
  normalizeL1(unnormalised);
  EXPECT_DOUBLE_EQ(unnormalised.sum(), 1.0);
  EXPECT_DOUBLE_EQ(unnormalised.weightOf(2), 0.75);
}

TEST(FeatureVector, GroupsFeaturesByNodeInOrder) {
  const FeatureVector fv = FeatureVector::fromPairs({{7, 3}, {2, 1}, {7, 0}, {2, 5}, {9, 4}});
  ASSERT_EQ(fv.size(), 3U);
  EXPECT_EQ(fv.node(0), 2U);
  EXPECT_EQ(std::vector<int>(fv.features(0).begin(), fv.features(0).end()),
            (std::vector<int>{1, 5}));
  EXPECT_EQ(std::vector<int>(fv.featuresOf(7).begin(), fv.featuresOf(7).end()),
            (std::vector<int>{0, 3}));
  EXPECT_TRUE(fv.featuresOf(3).empty());
  EXPECT_EQ(fv.featureCount(), 5U);
}

TEST(ParallelFor, VisitsEveryItemOnceAndRethrows) {
  std::vector<int> visits(1000, 0);
  parallelFor(visits.size(), 3, [&](std::size_t i, int) { ++visits[i]; });
  EXPECT_TRUE(std::all_of(visits.begin(), visits.end(), [](int v) { return v == 1; }));
  EXPECT_THROW(parallelFor(100, 3,
                           [](std::size_t i, int) {
                             if (i == 42) throw std::runtime_error("boom");
                           }),
               std::runtime_error);
}

TEST(VocabularyTraining, BuildsABoundedTreeWithWeightedWords) {
  const Vocabulary v = trainVocabulary(scenes().images, smallOptions());
  ASSERT_FALSE(v.empty());
  EXPECT_EQ(v.branching(), 4);
  EXPECT_EQ(v.levels(), 3);
  EXPECT_GT(v.wordCount(), 30U);
  EXPECT_LE(v.wordCount(), 64U);
  EXPECT_EQ(v.tree().training_images, 48U);
  EXPECT_EQ(v.tree().training_descriptors, 48U * 60U);
  for (WordId w = 0; w < v.wordCount(); ++w) {
    EXPECT_LE(v.nodeDepth(v.wordNode(w)), 3);
    EXPECT_GE(v.wordWeight(w), 0.0);
    EXPECT_LE(v.wordWeight(w), std::log(48.0) + 1e-12);
  }
}

TEST(VocabularyTraining, NoisyCopiesOfOnePrototypeMostlyShareAWord) {
  const auto& s = scenes();
  const Vocabulary v = trainVocabulary(s.images, smallOptions());
  std::mt19937 rng(3);
  int same = 0;
  const int trials = 200;
  for (int t = 0; t < trials; ++t) {
    const int row = static_cast<int>(rng() % static_cast<unsigned>(s.prototypes.rows));
    std::uint8_t a[32], b[32];
    test::noisyCopy(s.prototypes, row, 8, rng, a);
    test::noisyCopy(s.prototypes, row, 8, rng, b);
    same += v.wordOf(a) == v.wordOf(b) ? 1 : 0;
  }
  EXPECT_GT(same, trials * 8 / 10);
}

TEST(VocabularyTraining, SameSeedSameTreeWhateverTheThreadCount) {
  // Over 65536 descriptors, so the root's assignment is split across threads as well.
  const auto big = test::makeScenes(16, 200, 160, 450, 10, 5);
  VocabularyTrainingOptions one = smallOptions(1);
  one.levels = 2;
  VocabularyTrainingOptions three = one;
  three.threads = 3;
  const Vocabulary a = trainVocabulary(big.images, one);
  const Vocabulary b = trainVocabulary(big.images, three);
  EXPECT_EQ(a.tree(), b.tree());
  VocabularyTrainingOptions other_seed = one;
  other_seed.seed = 99;
  EXPECT_NE(trainVocabulary(big.images, other_seed).tree(), a.tree());
}

TEST(VocabularyTraining, ReportsProgressUpToTheTotal) {
  VocabularyTrainingOptions o = smallOptions(2);
  std::size_t last_done = 0;
  std::size_t total = 0;
  bool monotone = true;
  o.progress = [&](const VocabularyTrainingProgress& p) {
    if (p.stage == "clustering") {
      monotone = monotone && p.done >= last_done;
      last_done = p.done;
      total = p.total;
    }
  };
  trainVocabulary(scenes().images, o);
  EXPECT_TRUE(monotone);
  EXPECT_EQ(total, 48U * 60U * 3U);
  EXPECT_EQ(last_done, total);
}

TEST(VocabularyTraining, RejectsBadOptionsAndInput) {
  VocabularyTrainingOptions o = smallOptions();
  o.branching = 1;
  EXPECT_THROW(trainVocabulary(scenes().images, o), std::invalid_argument);
  o = smallOptions();
  o.levels = 0;
  EXPECT_THROW(trainVocabulary(scenes().images, o), std::invalid_argument);
  EXPECT_THROW(trainVocabulary(std::vector<cv::Mat>{cv::Mat()}, smallOptions()),
               std::invalid_argument);
  const std::vector<cv::Mat> wrong_type = {cv::Mat(5, 32, CV_32F, cv::Scalar(0))};
  try {
    trainVocabulary(wrong_type, smallOptions());
    FAIL() << "expected an exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("CV_8UC1"), std::string::npos);
  }
}

TEST(VocabularyTraining, IdenticalDescriptorsGiveOneWord) {
  const std::vector<cv::Mat> images = {cv::Mat(30, 32, CV_8UC1, cv::Scalar(0x5A)),
                                       cv::Mat(30, 32, CV_8UC1, cv::Scalar(0x5A))};
  const Vocabulary v = trainVocabulary(images, smallOptions());
  EXPECT_EQ(v.wordCount(), 1U);
  EXPECT_DOUBLE_EQ(v.wordWeight(0), 0.0);  // in every image: idf = log(2/2)
}

TEST(VocabularyTransform, BowIsNormalisedAndSelfScoresOne) {
  const auto& s = scenes();
  const Vocabulary v = trainVocabulary(s.images, smallOptions());
  for (int i = 0; i < 8; ++i) {
    const BowVector bow = v.transform(s.images[i]);
    ASSERT_FALSE(bow.empty());
    EXPECT_NEAR(bow.sum(), 1.0, 1e-12);
    EXPECT_TRUE(std::is_sorted(bow.begin(), bow.end(),
                               [](const auto& a, const auto& b) { return a.word < b.word; }));
    EXPECT_DOUBLE_EQ(l1Score(bow, bow), 1.0);
  }
  EXPECT_TRUE(v.transform(cv::Mat()).empty());
  EXPECT_THROW(v.transform(cv::Mat(3, 16, CV_8UC1)), std::invalid_argument);
  EXPECT_THROW(Vocabulary().transform(s.images[0]), std::logic_error);
}

TEST(VocabularyTransform, ImagesOfTheSamePlaceScoreHigherThanOtherPlaces) {
  const auto& s = scenes();
  const Vocabulary v = trainVocabulary(s.images, smallOptions());
  // A fresh image of each place, never seen in training.
  std::mt19937 rng(21);
  for (int place = 0; place < 4; ++place) {
    const BowVector query = v.transform(test::imageOf(s.prototypes, s.rows[place], 8, rng));
    const double same = l1Score(query, v.transform(s.images[place + 8]));
    const double other = l1Score(query, v.transform(s.images[(place + 1) % 8]));
    EXPECT_GT(same, other + 0.1) << "place " << place;
  }
}

TEST(VocabularyTransform, DirectIndexFilesFeaturesAtTheChosenLevel) {
  const auto& s = scenes();
  const Vocabulary v = trainVocabulary(s.images, smallOptions());
  BowVector bow;
  FeatureVector leaves;
  v.transform(s.images[0], 0, bow, leaves);
  EXPECT_EQ(bow, v.transform(s.images[0]));
  EXPECT_EQ(leaves.featureCount(), static_cast<std::size_t>(s.images[0].rows));
  const std::vector<WordId> words = v.words(s.images[0]);
  for (std::size_t i = 0; i < leaves.size(); ++i) {
    for (const int f : leaves.features(i)) EXPECT_EQ(v.wordNode(words[f]), leaves.node(i));
  }
  FeatureVector level1;
  v.transform(s.images[0], 2, bow, level1);
  for (std::size_t i = 0; i < level1.size(); ++i) EXPECT_EQ(v.nodeDepth(level1.node(i)), 1);
  FeatureVector root;
  v.transform(s.images[0], 5, bow, root);
  ASSERT_EQ(root.size(), 1U);
  EXPECT_EQ(root.node(0), 0U);
  EXPECT_EQ(root.featureCount(), static_cast<std::size_t>(s.images[0].rows));
}

TEST(VocabularyWeighting, ParsesNamesAndRejectsUnknown) {
  for (const WordWeighting w :
       {WordWeighting::kTfIdf, WordWeighting::kTf, WordWeighting::kIdf, WordWeighting::kBinary}) {
    EXPECT_EQ(parseWordWeighting(toString(w)), w);
  }
  EXPECT_THROW(parseWordWeighting("bm25"), std::invalid_argument);
}

TEST(VocabularyWeighting, BinaryWeightingGivesEqualWeights) {
  VocabularyTrainingOptions o = smallOptions();
  o.weighting = WordWeighting::kBinary;
  const Vocabulary v = trainVocabulary(scenes().images, o);
  const BowVector bow = v.transform(scenes().images[0]);
  for (const BowEntry& e : bow) EXPECT_DOUBLE_EQ(e.weight, 1.0 / static_cast<double>(bow.size()));
}

TEST(VocabularyTree, RejectsMalformedTrees) {
  VocabularyTree t;
  t.branching = 2;
  t.levels = 2;
  t.parents = {kNoParent, 0, 0, 0};  // three children for k = 2
  t.centres.resize(4);
  t.weights.assign(4, 1.0);
  EXPECT_THROW(Vocabulary{t}, std::invalid_argument);
  t.parents = {kNoParent, 0, 2};  // parent after child
  t.centres.resize(3);
  t.weights.assign(3, 1.0);
  EXPECT_THROW(Vocabulary{t}, std::invalid_argument);
  t.parents = {kNoParent, 0, 1, 2};  // depth 3 > levels 2
  t.centres.resize(4);
  t.weights.assign(4, 1.0);
  EXPECT_THROW(Vocabulary{t}, std::invalid_argument);
  t.parents = {kNoParent, 0, 0};
  t.centres.resize(3);
  t.weights = {0.0, 1.0, std::nan("")};
  EXPECT_THROW(Vocabulary{t}, std::invalid_argument);
  t.weights = {0.0, 1.0, 2.0};
  EXPECT_EQ(Vocabulary{t}.wordCount(), 2U);
}

}  // namespace
}  // namespace edgeslam
