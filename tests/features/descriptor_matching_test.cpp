#include "features/descriptor_matching.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "features/descriptor_distance.h"

namespace edgeslam {
namespace {

cv::Mat randomDescriptors(int n, int seed) {
  cv::Mat d(n, 32, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(d, cv::RNG::UNIFORM, 0, 256);
  return d;
}

// Copy of `d` with `bits` random bits flipped per row.
cv::Mat perturbed(const cv::Mat& d, int bits, int seed) {
  cv::Mat out = d.clone();
  cv::RNG rng(seed);
  for (int r = 0; r < out.rows; ++r) {
    for (int k = 0; k < bits; ++k) {
      const int bit = rng.uniform(0, 256);
      out.at<std::uint8_t>(r, bit / 8) ^= static_cast<std::uint8_t>(1u << (bit % 8));
    }
  }
  return out;
}

TEST(FindBestTwo, FindsBestAndSecond) {
  const cv::Mat train = randomDescriptors(50, 1);
  const cv::Mat query = perturbed(train.row(17), 3, 2);
  const BestTwo all = findBestTwo(query.ptr<std::uint8_t>(0), train);
  EXPECT_EQ(all.index, 17);
  EXPECT_LE(all.distance, 3);
  EXPECT_GT(all.second_distance, 60);
  EXPECT_TRUE(all.passesRatio(0.8));
  const std::vector<int> subset = {3, 9, 40};
  const BestTwo some = findBestTwo(query.ptr<std::uint8_t>(0), train, subset);
  EXPECT_TRUE(some.index == 3 || some.index == 9 || some.index == 40);
  EXPECT_FALSE(findBestTwo(query.ptr<std::uint8_t>(0), train, {}).passesRatio(1.0));
}

TEST(MatchBruteForce, RecoversPermutedCorrespondences) {
  const int n = 300;
  const cv::Mat query = randomDescriptors(n, 5);
  // train row t is query row perm[t], with a few bits flipped.
  std::vector<int> perm(n);
  for (int i = 0; i < n; ++i) perm[i] = (i * 7 + 3) % n;
  cv::Mat train(n, 32, CV_8UC1);
  for (int t = 0; t < n; ++t) query.row(perm[t]).copyTo(train.row(t));
  train = perturbed(train, 10, 6);
  std::vector<cv::KeyPoint> kq(n, cv::KeyPoint(0.f, 0.f, 31.f, 30.f));
  std::vector<cv::KeyPoint> kt(n, cv::KeyPoint(0.f, 0.f, 31.f, 50.f));
  const auto matches = matchBruteForce(kq, query, kt, train);
  ASSERT_EQ(static_cast<int>(matches.size()), n);
  for (const cv::DMatch& m : matches) EXPECT_EQ(perm[m.trainIdx], m.queryIdx);
}

TEST(MatchBruteForce, RotationCheckDropsInconsistentMatches) {
  const int n = 100;
  const cv::Mat query = randomDescriptors(n, 8);
  const cv::Mat train = perturbed(query, 5, 9);
  std::vector<cv::KeyPoint> kq(n, cv::KeyPoint(0.f, 0.f, 31.f, 10.f));
  std::vector<cv::KeyPoint> kt(n, cv::KeyPoint(0.f, 0.f, 31.f, 15.f));
  for (int i = 0; i < 10; ++i) kt[i].angle = 10.f + 33.f * static_cast<float>(i + 1);
  const auto matches = matchBruteForce(kq, query, kt, train);
  EXPECT_EQ(matches.size(), 90u);
  MatchOptions no_check;
  no_check.check_orientation = false;
  EXPECT_EQ(matchBruteForce(kq, query, kt, train, no_check).size(), 100u);
}

TEST(MatchInWindow, OnlyMatchesNearbyCandidatesOfTheSameLevel) {
  const cv::Mat query = randomDescriptors(3, 11);
  const cv::Mat train = perturbed(query, 4, 12);
  std::vector<cv::KeyPoint> kq = {cv::KeyPoint(100.f, 100.f, 31.f, 0.f),
                                  cv::KeyPoint(300.f, 200.f, 31.f, 0.f),
                                  cv::KeyPoint(500.f, 400.f, 31.f, 0.f)};
  std::vector<cv::KeyPoint> kt = {cv::KeyPoint(110.f, 95.f, 31.f, 0.f),    // near: matches
                                  cv::KeyPoint(400.f, 200.f, 31.f, 0.f),   // too far
                                  cv::KeyPoint(505.f, 400.f, 31.f, 0.f)};  // other level
  kt[2].octave = 2;
  const FeatureGrid grid({0, 640, 0, 480}, kt);
  MatchOptions options;
  options.check_orientation = false;
  const auto matches = matchInWindow(kq, query, kt, train, grid, 30.f, options);
  ASSERT_EQ(matches.size(), 1u);
  EXPECT_EQ(matches[0].queryIdx, 0);
  EXPECT_EQ(matches[0].trainIdx, 0);
  EXPECT_EQ(matchInWindow(kq, query, kt, train, grid, 30.f, options, 2).size(), 2u);
}

TEST(Matching, RejectsMismatchedInput) {
  const cv::Mat d = randomDescriptors(3, 1);
  const std::vector<cv::KeyPoint> two(2, cv::KeyPoint(0.f, 0.f, 31.f));
  const std::vector<cv::KeyPoint> three(3, cv::KeyPoint(0.f, 0.f, 31.f));
  EXPECT_THROW(matchBruteForce(two, d, three, d), std::invalid_argument);
  const FeatureGrid grid({0, 640, 0, 480}, two);
  EXPECT_THROW(matchInWindow(three, d, three, d, grid, 10.f), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
