// The bag-of-words new-point search on two real 7-Scenes (redkitchen) keyframes ten frames apart at
// their ground-truth poses, against the epipolar band search: its pairs must agree with the depth
// images as well, and it must find most of what the band search finds. Skipped without the data.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "features/frame_features_builder.h"
#include "features/orb_extractor.h"
#include "map/map_matching.h"
#include "map/seven_scenes_frames.h"
#include "place/vocabulary_training.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr int kFirst = 255, kSecond = 265;  // 4 cm and 1.5 degrees apart

using test::sevenScenesCamera;
using RealFrame = test::SevenScenesFrame;
const RealFrame& realFrame(int index) {
  return test::sevenScenesFrame(index);
}

// k = 10, L = 4 on every 25th frame: the direct index at depth 2 has up to 100 nodes, as with the
// default vocabulary (k = 10, L = 5).
const Vocabulary& vocabulary() {
  static const Vocabulary v = [] {
    OrbExtractor extractor;
    std::vector<cv::Mat> training;
    for (int i = 0; i < 1000; i += 25) {
      const cv::Mat grey =
          cv::imread(test::sevenScenesFramePath(i, "color.jpg"), cv::IMREAD_GRAYSCALE);
      if (grey.empty())
        throw std::runtime_error("cannot read " + test::sevenScenesFramePath(i, "color.jpg"));
      training.push_back(extractor.extract(grey).descriptors);
    }
    VocabularyTrainingOptions options;
    options.branching = 10;
    options.levels = 4;
    options.threads = 2;
    return trainVocabulary(training, options);
  }();
  return v;
}

std::shared_ptr<KeyFramePlace> describe(const FrameFeatures& features) {
  auto place = std::make_shared<KeyFramePlace>();
  place->direct_index_depth = 2;
  place->vocabulary = &vocabulary();
  vocabulary().transform(features.descriptors, vocabulary().levels() - 2, place->bow,
                         place->features);
  return place;
}

// Colour and depth are not perfectly registered: only keypoints on locally smooth depth are judged.
bool depthIsSmooth(const cv::Mat& depth, const cv::KeyPoint& kp) {
  constexpr int kHalf = 3;
  const int x = cvRound(kp.pt.x), y = cvRound(kp.pt.y);
  if (x < kHalf || y < kHalf || x >= depth.cols - kHalf || y >= depth.rows - kHalf) return false;
  double lo = 0.0, hi = 0.0;
  cv::minMaxLoc(depth(cv::Rect(x - kHalf, y - kHalf, 2 * kHalf + 1, 2 * kHalf + 1)), &lo, &hi);
  return lo > 0.0 && hi - lo < 0.02 * lo;
}

Eigen::Vector3d pointFromDepth(const RealFrame& frame, std::size_t i, const PinholeCamera& camera) {
  const cv::Point2f& pt = frame.features->keypoints[i].pt;
  return frame.T_cw.inverse() * (camera.unproject({pt.x, pt.y}) * frame.features->depth[i]);
}

// Pairs whose keypoints both have smooth depth are judged: the two depth points (each through its
// frame's ground-truth pose) must be the same point, within 3 cm + 3 % of the distance.
struct Judgement {
  int judged = 0;
  int agreeing = 0;
  double share() const { return judged == 0 ? 0.0 : static_cast<double>(agreeing) / judged; }
};

Judgement judge(const std::vector<std::pair<std::size_t, std::size_t>>& pairs, const RealFrame& a,
                const RealFrame& b, const PinholeCamera& camera) {
  Judgement out;
  for (const auto& [i, j] : pairs) {
    if (!a.features->hasDepth(i) || !depthIsSmooth(a.depth, a.features->keypoints[i])) continue;
    if (!b.features->hasDepth(j) || !depthIsSmooth(b.depth, b.features->keypoints[j])) continue;
    ++out.judged;
    const Eigen::Vector3d xa = pointFromDepth(a, i, camera);
    const Eigen::Vector3d xb = pointFromDepth(b, j, camera);
    out.agreeing += (xa - xb).norm() < 0.03 + 0.03 * a.features->depth[i];
  }
  return out;
}

double medianMs(int runs, const std::function<void()>& call) {
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    const auto start = std::chrono::steady_clock::now();
    call();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

class TriangulationByBowRealData : public ::testing::Test {
 protected:
  void SetUp() override {
    EDGESLAM_REQUIRE_SHARED(test::kSevenScenesSequence);
    const RealFrame& a = realFrame(kFirst);
    const RealFrame& b = realFrame(kSecond);
    MutexLock lock(map_.updateMutex());
    kf1_ = map_.createKeyFrame(kFirst, kFirst / 30.0, a.features, a.T_cw);
    kf2_ = map_.createKeyFrame(kSecond, kSecond / 30.0, b.features, b.T_cw);
  }

  PinholeCamera camera_ = sevenScenesCamera();
  Map map_;
  KeyFrame* kf1_ = nullptr;
  KeyFrame* kf2_ = nullptr;
};

TEST_F(TriangulationByBowRealData, AgreesWithDepthAndFindsMostOfTheBandPairs) {
  kf1_->setPlace(describe(kf1_->features()));
  kf2_->setPlace(describe(kf2_->features()));
  ASSERT_TRUE(canMatchForTriangulationByBow(*kf1_, *kf2_));
  const RealFrame& a = realFrame(kFirst);
  const RealFrame& b = realFrame(kSecond);
  for (const bool monocular : {true, false}) {
    const auto band = matchForTriangulation(*kf1_, *kf2_, camera_, monocular);
    const auto bow = matchForTriangulationByBow(*kf1_, *kf2_, camera_, monocular);
    const Judgement band_check = judge(band, a, b, camera_);
    const Judgement bow_check = judge(bow, a, b, camera_);
    std::size_t common = 0;
    for (const auto& pair : bow) common += std::binary_search(band.begin(), band.end(), pair);
    const double band_ms =
        medianMs(21, [&] { (void)matchForTriangulation(*kf1_, *kf2_, camera_, monocular); });
    const double bow_ms =
        medianMs(21, [&] { (void)matchForTriangulationByBow(*kf1_, *kf2_, camera_, monocular); });
    std::printf(
        "[%s] band: %zu pairs, %.1f %% of %d judged agree with depth, %.3f ms | bow: %zu pairs "
        "(%zu also found by band), %.1f %% of %d agree, %.3f ms\n",
        monocular ? "mono" : "rgbd", band.size(), 100.0 * band_check.share(), band_check.judged,
        band_ms, bow.size(), common, 100.0 * bow_check.share(), bow_check.judged, bow_ms);

    EXPECT_GT(band.size(), 150u);
    EXPECT_GT(bow_check.judged, 60);
    EXPECT_GT(bow_check.share(), 0.9);
    EXPECT_GT(bow_check.share(), band_check.share() - 0.03);
    // Pairs under different nodes are out of reach; about two thirds remain.
    EXPECT_GT(static_cast<double>(bow.size()), 0.6 * static_cast<double>(band.size()));
    for (const auto& [i, j] : bow) {
      EXPECT_EQ(kf1_->point(i), nullptr);
      EXPECT_EQ(kf2_->point(j), nullptr);
    }
  }
}

TEST_F(TriangulationByBowRealData, WithoutFeatureVectorsItIsTheBandSearch) {
  for (const bool monocular : {true, false}) {
    const auto band = matchForTriangulation(*kf1_, *kf2_, camera_, monocular);
    EXPECT_GT(band.size(), 150u);
    EXPECT_EQ(matchForTriangulationByBow(*kf1_, *kf2_, camera_, monocular), band);
  }
  kf1_->setPlace(describe(kf1_->features()));  // one side only
  EXPECT_EQ(matchForTriangulationByBow(*kf1_, *kf2_, camera_, true),
            matchForTriangulation(*kf1_, *kf2_, camera_, true));
}

}  // namespace
}  // namespace edgeslam
