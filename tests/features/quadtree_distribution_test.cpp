#include "features/quadtree_distribution.h"

#include <gtest/gtest.h>

#include <algorithm>

namespace edgeslam {
namespace {

std::vector<cv::KeyPoint> randomKeypoints(int n, const cv::Rect2f& region, int seed) {
  cv::RNG rng(seed);
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < n; ++i) {
    kps.emplace_back(rng.uniform(region.x, region.x + region.width),
                     rng.uniform(region.y, region.y + region.height), 7.f, -1.f,
                     rng.uniform(1.f, 100.f));
  }
  return kps;
}

TEST(QuadtreeDistribution, KeepsAllWhenFewer) {
  const auto kps = randomKeypoints(30, {0, 0, 100, 100}, 1);
  EXPECT_EQ(distributeQuadtree(kps, {0, 0, 100, 100}, 50).size(), 30u);
  EXPECT_TRUE(distributeQuadtree(kps, {0, 0, 100, 100}, 0).empty());
}

TEST(QuadtreeDistribution, ReturnsTheTargetCountSpreadOut) {
  const cv::Rect2f region(0, 0, 640, 480);
  // A dense cluster in one corner plus a sparse background: the cluster must not take everything.
  auto kps = randomKeypoints(5000, {0, 0, 100, 100}, 2);
  const auto background = randomKeypoints(400, region, 3);
  kps.insert(kps.end(), background.begin(), background.end());
  const auto selected = distributeQuadtree(kps, region, 300);
  ASSERT_EQ(selected.size(), 300u);
  const auto in_cluster =
      std::count_if(selected.begin(), selected.end(),
                    [](const cv::KeyPoint& k) { return k.pt.x < 100 && k.pt.y < 100; });
  // The cluster covers 3% of the area; an even spread gives it a small share.
  EXPECT_LT(in_cluster, 60);
}

TEST(QuadtreeDistribution, PrefersTheStrongestInANode) {
  // Two keypoints a pixel apart with a target of one: the stronger one survives.
  std::vector<cv::KeyPoint> kps = {cv::KeyPoint(10.f, 10.f, 7.f, -1.f, 5.f),
                                   cv::KeyPoint(11.f, 10.f, 7.f, -1.f, 50.f)};
  const auto selected = distributeQuadtree(kps, {0, 0, 20, 20}, 1);
  ASSERT_EQ(selected.size(), 1u);
  EXPECT_FLOAT_EQ(selected[0].response, 50.f);
}

TEST(QuadtreeDistribution, CoincidentKeypointsDoNotLoopForever) {
  std::vector<cv::KeyPoint> kps(100, cv::KeyPoint(5.f, 5.f, 7.f));
  for (int i = 0; i < 100; ++i) kps[i].response = static_cast<float>(i);
  const auto selected = distributeQuadtree(kps, {0, 0, 10, 10}, 10);
  ASSERT_EQ(selected.size(), 1u);
  EXPECT_FLOAT_EQ(selected[0].response, 99.f);
}

}  // namespace
}  // namespace edgeslam
