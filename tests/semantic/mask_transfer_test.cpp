#include "semantic/mask_transfer.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace edgeslam {
namespace {

cv::Point2f apply(const cv::Matx23d& m, cv::Point2f p) {
  return {static_cast<float>(m(0, 0) * p.x + m(0, 1) * p.y + m(0, 2)),
          static_cast<float>(m(1, 0) * p.x + m(1, 1) * p.y + m(1, 2))};
}

cv::Mat1b warpedTruth(const cv::Mat1b& mask, const cv::Matx23d& m) {
  cv::Mat1b out;
  cv::warpAffine(mask, out, cv::Mat(m), mask.size(), cv::INTER_NEAREST);
  return out;
}

double iou(const cv::Mat1b& a, const cv::Mat1b& b) {
  return static_cast<double>(cv::countNonZero(a & b)) / cv::countNonZero(a | b);
}

struct Scene {
  cv::Mat1b labels = cv::Mat1b::zeros(480, 640);
  cv::Matx23d background = cv::Matx23d(1, 0, 6, 0, 1, -4);
  cv::Matx23d person;                                    // instance 1: a similarity of its own
  cv::Matx23d walker = cv::Matx23d(1, 0, -15, 0, 1, 2);  // instance 2: few matches, translation
  std::vector<cv::Point2f> keyframe, current;

  Scene() {
    cv::ellipse(labels, cv::Point(200, 250), cv::Size(50, 150), 0, 0, 360, cv::Scalar(1),
                cv::FILLED);
    cv::rectangle(labels, cv::Rect(420, 200, 60, 180), cv::Scalar(2), cv::FILLED);
    cv::rectangle(labels, cv::Rect(560, 20, 40, 40), cv::Scalar(3),
                  cv::FILLED);  // no matches on or near it
    person = cv::getRotationMatrix2D(cv::Point2f(200, 250), 4.0, 1.05);
    person(0, 2) += 18;
    person(1, 2) += 9;
    cv::RNG rng(3);
    for (int i = 0; i < 400; ++i) {
      const cv::Point2f p(rng.uniform(0.0f, 639.0f), rng.uniform(0.0f, 479.0f));
      const int label = labels(cvFloor(p.y), cvFloor(p.x));
      const bool near_unmatched = cv::Rect(540, 0, 100, 80).contains(p);
      if (label == 0 && !near_unmatched) add(p, apply(background, p));
      if (label == 1) add(p, apply(person, p));
    }
    add({430, 250}, apply(walker, {430, 250}));
    add({460, 300}, apply(walker, {460, 300}));
    add({445, 350}, apply(walker, {445, 350}));
    // Outliers on the person: gross mismatches RANSAC must reject.
    add({190, 200}, {500, 50});
    add({210, 300}, {20, 400});
  }
  void add(cv::Point2f from, cv::Point2f to) {
    keyframe.push_back(from);
    current.push_back(to);
  }
};

TEST(MaskTransfer, MovesEachInstanceByItsOwnMotion) {
  const Scene scene;
  const MaskTransferResult result = transferLabels(scene.labels, scene.keyframe, scene.current);
  ASSERT_EQ(result.instances.size(), 3u);
  EXPECT_EQ(result.background.motion, InstanceMotion::kSimilarity);
  EXPECT_EQ(result.instances[0].label, 1);
  EXPECT_EQ(result.instances[0].motion, InstanceMotion::kSimilarity);
  EXPECT_EQ(result.instances[1].motion, InstanceMotion::kTranslation);
  EXPECT_EQ(result.instances[2].motion, InstanceMotion::kBackground);
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(result.instances[0].warp(r, c), scene.person(r, c), c == 2 ? 1.0 : 0.01);
    }
  }
  const std::vector<cv::Matx23d> truths = {scene.person, scene.walker, scene.background};
  for (int label = 1; label <= 3; ++label) {
    const cv::Mat1b truth = warpedTruth(scene.labels == label, truths[label - 1]);
    EXPECT_GT(iou(result.labels == label, truth), 0.95) << "label " << label;
  }
  EXPECT_EQ(cv::countNonZero(result.mask != ((result.labels > 0) & 255)), 0);
}

TEST(MaskTransfer, BinaryMaskUsesConnectedComponentsAsInstances) {
  const Scene scene;
  const cv::Mat1b mask = (scene.labels > 0) & 255;
  const MaskTransferResult result = transferMask(mask, scene.keyframe, scene.current);
  ASSERT_EQ(result.instances.size(), 3u);
  cv::Mat1b truth = warpedTruth(scene.labels == 1, scene.person) |
                    warpedTruth(scene.labels == 2, scene.walker) |
                    warpedTruth(scene.labels == 3, scene.background);
  EXPECT_GT(iou(result.mask, truth), 0.95);
}

TEST(MaskTransfer, WithoutMatchesTheMaskStaysWhereItWas) {
  const Scene scene;
  const MaskTransferResult result = transferLabels(scene.labels, {}, {});
  EXPECT_EQ(result.background.motion, InstanceMotion::kIdentity);
  EXPECT_EQ(cv::countNonZero(result.labels != scene.labels), 0);
}

TEST(MaskTransfer, FewBackgroundMatchesGiveTheirMedianTranslation) {
  const Scene scene;
  const std::vector<cv::Point2f> from = {{20, 20}, {600, 400}, {300, 40}, {30, 450}};
  const std::vector<cv::Point2f> to = {{25, 22}, {605, 402}, {305, 42}, {90, 300}};  // an outlier
  const MaskTransferResult result = transferLabels(scene.labels, from, to);
  EXPECT_EQ(result.background.motion, InstanceMotion::kTranslation);
  for (const auto& instance : result.instances) {
    EXPECT_EQ(instance.motion, InstanceMotion::kBackground);
    EXPECT_DOUBLE_EQ(instance.warp(0, 2), 5.0);
    EXPECT_DOUBLE_EQ(instance.warp(1, 2), 2.0);
  }
}

TEST(MaskTransfer, EmptyLabelsAndBadInput) {
  const MaskTransferResult result = transferLabels(cv::Mat1b::zeros(48, 64), {{1, 1}}, {{2, 2}});
  EXPECT_EQ(cv::countNonZero(result.mask), 0);
  EXPECT_TRUE(result.instances.empty());
  EXPECT_THROW(transferLabels(cv::Mat1b::zeros(48, 64), {{1, 1}}, {}), std::invalid_argument);
  EXPECT_THROW(transferLabels(cv::Mat1b(), {}, {}), std::invalid_argument);
}

TEST(MaskTransfer, InstancesMovedOutOfTheImageDisappear) {
  cv::Mat1b labels = cv::Mat1b::zeros(100, 100);
  labels(cv::Rect(10, 10, 20, 20)).setTo(1);
  const std::vector<cv::Point2f> from = {{15, 15}, {20, 20}, {25, 12}};
  const std::vector<cv::Point2f> to = {{515, 15}, {520, 20}, {525, 12}};
  const MaskTransferResult result = transferLabels(labels, from, to);
  EXPECT_EQ(cv::countNonZero(result.labels), 0);
}

TEST(MaskTransfer, APersonCutByTheImageEdgeComesInWhole) {
  // The keyframe sees 30 px of someone walking in from the left; 40 px later the mask must cover
  // what entered behind them, not only the sliver moved inwards. Walking out to the right edge
  // brings nothing in, and growing can be switched off.
  cv::Mat1b labels = cv::Mat1b::zeros(480, 640);
  labels(cv::Rect(0, 100, 30, 300)).setTo(1);
  labels(cv::Rect(600, 120, 40, 200)).setTo(2);
  std::vector<cv::Point2f> from, to;
  for (int y = 110; y < 390; y += 20) {
    from.emplace_back(10.f + static_cast<float>(y % 3), static_cast<float>(y));
    to.push_back(from.back() + cv::Point2f(40.f, 0.f));
    from.emplace_back(615.f + static_cast<float>(y % 5), static_cast<float>(y));
    to.push_back(from.back() + cv::Point2f(10.f, 0.f));
  }
  const MaskTransferResult grown = transferLabels(labels, from, to);
  EXPECT_EQ(cv::countNonZero(grown.labels == 1), 70 * 300);
  EXPECT_EQ(cv::countNonZero(grown.labels(cv::Rect(0, 100, 70, 300)) == 1), 70 * 300);
  EXPECT_EQ(cv::countNonZero(grown.labels == 2), 30 * 200);

  MaskTransferOptions options;
  options.grow_cut_edges = false;
  const MaskTransferResult sliver = transferLabels(labels, from, to, options);
  EXPECT_EQ(cv::countNonZero(sliver.labels == 1), 30 * 300);
  EXPECT_EQ(cv::countNonZero(sliver.labels(cv::Rect(40, 100, 30, 300)) == 1), 30 * 300);
}

TEST(MaskTransfer, TooFewOrDisagreeingMatchesFallBackToThePredictedMotion) {
  // A person walking behind something keeps two stray matches: they must not throw the mask
  // across the image; the instance goes on with the motion its caller predicts.
  cv::Mat1b labels = cv::Mat1b::zeros(480, 640);
  labels(cv::Rect(100, 100, 60, 200)).setTo(1);
  labels(cv::Rect(400, 100, 60, 200)).setTo(2);
  const std::vector<cv::Point2f> from = {
      {120, 150}, {140, 250}, {420, 150}, {430, 200}, {440, 250}};
  const std::vector<cv::Point2f> to = {{320, 190}, {150, 240}, {430, 150}, {470, 230}, {400, 180}};
  PredictedWarps predicted;
  predicted[1] = cv::Matx23d(1, 0, 12, 0, 1, 0);
  const MaskTransferResult result =
      transferLabels(prepareLabels(labels, 12), from, to, {}, &predicted);
  ASSERT_EQ(result.instances.size(), 2u);
  EXPECT_EQ(result.instances[0].motion, InstanceMotion::kPredicted);
  EXPECT_DOUBLE_EQ(result.instances[0].warp(0, 2), 12.0);
  // Three matches that disagree, and no prediction: the background's motion (here none).
  EXPECT_NE(result.instances[1].motion, InstanceMotion::kTranslation);
  EXPECT_EQ(cv::countNonZero(result.labels == 2), 60 * 200);
}

}  // namespace
}  // namespace edgeslam
