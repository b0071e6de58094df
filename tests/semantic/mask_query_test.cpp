#include "semantic/mask_query.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace edgeslam {
namespace {

cv::Mat1b squareMask() {
  cv::Mat1b mask = cv::Mat1b::zeros(480, 640);
  mask(cv::Rect(100, 100, 50, 80)).setTo(255);  // x 100..149, y 100..179
  return mask;
}

TEST(InsideMask, TestsThePixelAndItsMargin) {
  const cv::Mat1b mask = squareMask();
  EXPECT_TRUE(insideMask(mask, {120.5f, 150.2f}, 0));
  EXPECT_FALSE(insideMask(mask, {95.0f, 150.0f}, 0));
  EXPECT_TRUE(insideMask(mask, {95.0f, 150.0f}, 5));
  EXPECT_FALSE(insideMask(mask, {94.0f, 150.0f}, 5));
  EXPECT_TRUE(insideMask(mask, {155.9f, 185.9f}, 6));
  EXPECT_FALSE(insideMask(mask, {-10.0f, 5000.0f}, 3));
  EXPECT_FALSE(insideMask(cv::Mat1b(), {1.0f, 1.0f}, 3));
}

TEST(DynamicCulling, DropsFeaturesInsideTheDilatedMask) {
  const cv::Mat1b mask = squareMask();
  const std::vector<cv::Point2f> points = {
      {120, 150},  // inside
      {10, 10},    // far away
      {147, 178},  // inside, near the corner
      {153, 150},  // 4 px right of the mask: inside the 5 px margin
      {156, 150},  // 7 px right: kept
      {-5, 20},    // outside the image: kept (cannot be on a masked object)
      {639.9f, 479.9f}};
  EXPECT_EQ(indicesOutsideMask(points, mask, 5), (std::vector<int>{1, 4, 5, 6}));
  EXPECT_EQ(indicesOutsideMask(points, mask, 0), (std::vector<int>{1, 3, 4, 5, 6}));
  std::vector<cv::KeyPoint> keypoints;
  for (const auto& p : points) keypoints.emplace_back(p, 7.0f);
  EXPECT_EQ(indicesOutsideMask(keypoints, mask, 5), (std::vector<int>{1, 4, 5, 6}));
}

TEST(DynamicCulling, AgreesWithInsideMaskOnRandomPoints) {
  const cv::Mat1b mask = squareMask();
  cv::RNG rng(7);
  std::vector<cv::Point2f> points;
  for (int i = 0; i < 2000; ++i) {
    points.emplace_back(rng.uniform(0.0f, 640.0f), rng.uniform(0.0f, 480.0f));
  }
  const std::vector<int> kept = indicesOutsideMask(points, mask, 4);
  std::vector<int> expected;
  for (int i = 0; i < static_cast<int>(points.size()); ++i) {
    if (!insideMask(mask, points[static_cast<std::size_t>(i)], 4)) expected.push_back(i);
  }
  EXPECT_EQ(kept, expected);
  EXPECT_LT(kept.size(), points.size());
}

TEST(DynamicCulling, EmptyMaskKeepsEverythingAndNegativeMarginIsAnError) {
  const std::vector<cv::Point2f> points = {{1, 1}, {2, 2}};
  EXPECT_EQ(indicesOutsideMask(points, cv::Mat1b(), 3), (std::vector<int>{0, 1}));
  EXPECT_EQ(indicesOutsideMask(points, cv::Mat1b::zeros(10, 10), 3), (std::vector<int>{0, 1}));
  EXPECT_THROW(indicesOutsideMask(points, squareMask(), -1), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
