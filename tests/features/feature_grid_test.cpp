#include "features/feature_grid.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

std::vector<int> bruteForce(const std::vector<cv::KeyPoint>& kps, float x, float y, float r,
                            int min_level, int max_level) {
  std::vector<int> out;
  for (int i = 0; i < static_cast<int>(kps.size()); ++i) {
    const cv::KeyPoint& kp = kps[i];
    if (min_level >= 0 && kp.octave < min_level) continue;
    if (max_level >= 0 && kp.octave > max_level) continue;
    if (std::abs(kp.pt.x - x) <= r && std::abs(kp.pt.y - y) <= r) out.push_back(i);
  }
  return out;
}

TEST(FeatureGrid, RadiusSearchEqualsBruteForce) {
  // Bounds as a distorted camera gives them (not starting at 0), points partly outside them.
  const PinholeCamera::Bounds bounds{-12.5, 651.0, -8.0, 490.0};
  cv::RNG rng(42);
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < 3000; ++i) {
    cv::KeyPoint kp(rng.uniform(-30.f, 680.f), rng.uniform(-30.f, 520.f), 31.f);
    kp.octave = rng.uniform(0, 8);
    kps.push_back(kp);
  }
  const FeatureGrid grid(bounds, kps, 10.0);
  EXPECT_EQ(grid.size(), kps.size());
  for (int q = 0; q < 500; ++q) {
    const float x = rng.uniform(-50.f, 700.f), y = rng.uniform(-50.f, 540.f);
    const float r = rng.uniform(0.f, 80.f);
    const int min_level = rng.uniform(-1, 8);
    const int max_level = rng.uniform(-1, 8);
    auto got = grid.featuresInArea(x, y, r, min_level, max_level);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, bruteForce(kps, x, y, r, min_level, max_level))
        << "query (" << x << ", " << y << ") r=" << r << " levels " << min_level << ".."
        << max_level;
  }
}

TEST(FeatureGrid, PointOnTheWindowEdgeIsIncluded) {
  const std::vector<cv::KeyPoint> kps = {cv::KeyPoint(100.f, 100.f, 31.f)};
  const FeatureGrid grid({0, 640, 0, 480}, kps);
  EXPECT_EQ(grid.featuresInArea(90.f, 100.f, 10.f).size(), 1u);
  EXPECT_TRUE(grid.featuresInArea(89.f, 100.f, 10.f).empty());
}

TEST(FeatureGrid, EmptyGridAndBadInput) {
  const FeatureGrid empty({0, 640, 0, 480}, {});
  EXPECT_TRUE(empty.featuresInArea(10.f, 10.f, 100.f).empty());
  EXPECT_TRUE(FeatureGrid().featuresInArea(10.f, 10.f, 100.f).empty());
  EXPECT_THROW(FeatureGrid({10, 5, 0, 480}, {}), std::invalid_argument);
  EXPECT_THROW(FeatureGrid({0, 640, 0, 480}, {}, 0.0), std::invalid_argument);
  const std::vector<cv::KeyPoint> nan_point = {cv::KeyPoint(std::nanf(""), 1.f, 31.f)};
  EXPECT_THROW(FeatureGrid({0, 640, 0, 480}, nan_point), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
