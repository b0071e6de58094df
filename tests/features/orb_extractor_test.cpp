#include "features/orb_extractor.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

// Blobs and edges at many sizes, so that every pyramid level finds corners.
cv::Mat syntheticScene(int width, int height, int seed) {
  cv::Mat image(height, width, CV_8UC1, cv::Scalar(128));
  cv::RNG rng(seed);
  for (int i = 0; i < 1500; ++i) {
    const cv::Point corner(rng.uniform(0, width), rng.uniform(0, height));
    const int size = rng.uniform(3, 60);
    cv::rectangle(image, corner, corner + cv::Point(size, rng.uniform(3, 60)),
                  cv::Scalar(rng.uniform(0, 256)), cv::FILLED);
  }
  cv::GaussianBlur(image, image, cv::Size(3, 3), 0.8);
  return image;
}

TEST(OrbExtractorOptions, RejectsBadValues) {
  auto bad = [](auto change) {
    OrbExtractorOptions options;
    change(options);
    return options;
  };
  EXPECT_THROW(OrbExtractor(bad([](auto& o) { o.num_features = -1; })), std::invalid_argument);
  EXPECT_THROW(OrbExtractor(bad([](auto& o) { o.scale_factor = 1.0; })), std::invalid_argument);
  EXPECT_THROW(OrbExtractor(bad([](auto& o) { o.num_levels = 0; })), std::invalid_argument);
  EXPECT_THROW(OrbExtractor(bad([](auto& o) { o.fast_threshold_min = 30; })),
               std::invalid_argument);
  EXPECT_THROW(OrbExtractor(bad([](auto& o) { o.edge_border = 10; })), std::invalid_argument);
  EXPECT_THROW(OrbExtractor(bad([](auto& o) { o.cell_size = 0; })), std::invalid_argument);
}

TEST(OrbExtractor, QuotasFollowAreaAndSumToTheTotal) {
  const OrbExtractor extractor;
  const auto& quota = extractor.featuresPerLevel();
  ASSERT_EQ(quota.size(), 8u);
  int sum = 0;
  for (int l = 0; l < 8; ++l) sum += quota[l];
  EXPECT_EQ(sum, 1000);
  for (int l = 1; l < 8; ++l) {
    EXPECT_NEAR(static_cast<double>(quota[l]) / quota[l - 1], 1.0 / 1.44, 0.1) << "level " << l;
  }
}

TEST(OrbExtractor, ExtractsConsistentOutput) {
  const cv::Mat image = syntheticScene(640, 480, 1);
  OrbExtractor extractor;
  const OrbFeatures f = extractor.extract(image);
  ASSERT_GT(f.keypoints.size(), 900u);
  ASSERT_LE(f.keypoints.size(), 1000u);
  ASSERT_EQ(f.descriptors.rows, static_cast<int>(f.keypoints.size()));
  ASSERT_EQ(f.descriptors.cols, 32);
  ASSERT_EQ(f.descriptors.type(), CV_8UC1);
  int previous_level = 0;
  for (const cv::KeyPoint& kp : f.keypoints) {
    EXPECT_GE(kp.octave, previous_level);  // ordered by level
    previous_level = kp.octave;
    const float scale = static_cast<float>(extractor.scaleLevels().scale(kp.octave));
    EXPECT_NEAR(kp.size, 31.f * scale, 1e-3f);
    EXPECT_GE(kp.angle, 0.f);
    EXPECT_LT(kp.angle, 360.f);
    EXPECT_GE(kp.response, 7.f);
    // edge_border (16) level pixels from every side.
    EXPECT_GE(kp.pt.x, 16.f * scale - 1.f);
    EXPECT_LE(kp.pt.x, 640.f - 16.f * scale + 1.f);
    EXPECT_GE(kp.pt.y, 16.f * scale - 1.f);
    EXPECT_LE(kp.pt.y, 480.f - 16.f * scale + 1.f);
  }
  EXPECT_EQ(previous_level, 7);
}

TEST(OrbExtractor, IsDeterministicAndAcceptsColour) {
  const cv::Mat grey = syntheticScene(320, 240, 2);
  cv::Mat bgr;
  cv::cvtColor(grey, bgr, cv::COLOR_GRAY2BGR);
  OrbExtractor extractor;
  const OrbFeatures a = extractor.extract(grey);
  const OrbFeatures b = extractor.extract(bgr);
  ASSERT_EQ(a.keypoints.size(), b.keypoints.size());
  EXPECT_EQ(cv::norm(a.descriptors, b.descriptors, cv::NORM_HAMMING), 0.0);
}

TEST(OrbExtractor, LevelsCanChangeAtRunTime) {
  const cv::Mat image = syntheticScene(640, 480, 3);
  OrbExtractor extractor;
  for (const int levels : {8, 4, 6, 1, 8}) {
    extractor.setNumLevels(levels);
    ASSERT_EQ(extractor.numLevels(), levels);
    ASSERT_EQ(extractor.scaleLevels().numLevels(), levels);
    const OrbFeatures f = extractor.extract(image);
    int max_level = 0;
    for (const cv::KeyPoint& kp : f.keypoints) max_level = std::max(max_level, kp.octave);
    EXPECT_EQ(max_level, levels - 1);
    EXPECT_GT(f.keypoints.size(), 900u) << levels << " levels";
  }
  EXPECT_THROW(extractor.setNumLevels(0), std::invalid_argument);
  EXPECT_EQ(extractor.numLevels(), 8);  // unchanged after a rejected change
  extractor.setNumFeatures(300);
  EXPECT_LE(extractor.extract(image).keypoints.size(), 300u);
}

TEST(OrbExtractor, SmallFlatAndBadImages) {
  OrbExtractor extractor;
  const OrbFeatures tiny = extractor.extract(cv::Mat(20, 20, CV_8UC1, cv::Scalar(3)));
  EXPECT_TRUE(tiny.keypoints.empty());
  EXPECT_EQ(tiny.descriptors.rows, 0);
  const OrbFeatures flat = extractor.extract(cv::Mat(480, 640, CV_8UC1, cv::Scalar(90)));
  EXPECT_TRUE(flat.keypoints.empty());
  EXPECT_THROW(extractor.extract(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(extractor.extract(cv::Mat(100, 100, CV_32FC1, cv::Scalar(0))),
               std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
