#include "features/steered_brief.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <set>
#include <stdexcept>

#include "features/descriptor_distance.h"

namespace edgeslam {
namespace {

TEST(SteeredBrief, PatternIsValidAndDeterministic) {
  const auto& pattern = steeredBriefPattern();
  std::set<std::tuple<float, float, float, float>> distinct;
  for (const BriefPair& p : pattern) {
    EXPECT_LE(p.x1 * p.x1 + p.y1 * p.y1, 225.f);
    EXPECT_LE(p.x2 * p.x2 + p.y2 * p.y2, 225.f);
    EXPECT_FALSE(p.x1 == p.x2 && p.y1 == p.y2);
    distinct.insert({p.x1, p.y1, p.x2, p.y2});
  }
  EXPECT_GT(distinct.size(), 250u);
  // Pinned values: a change of the generator silently invalidates every stored descriptor and
  // vocabulary, so it must show up here.
  auto same = [](const BriefPair& p, float x1, float y1, float x2, float y2) {
    return p.x1 == x1 && p.y1 == y1 && p.x2 == x2 && p.y2 == y2;
  };
  EXPECT_TRUE(same(pattern[0], 7, 1, -4, -7));
  EXPECT_TRUE(same(pattern[1], 3, 1, 5, -3));
  EXPECT_TRUE(same(pattern[255], 0, -11, -7, -6));
}

cv::Mat texture(int size, int seed) {
  cv::Mat image(size, size, CV_8UC1);
  cv::RNG rng(seed);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(image, image, cv::Size(5, 5), 1.5);
  return image;
}

TEST(SteeredBrief, RotatingImageAndAngleTogetherKeepsTheDescriptor) {
  const cv::Mat image = texture(81, 11);
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);
  // Point (40, 40) stays at the centre; its angle turns by +90 degrees.
  const std::vector<cv::KeyPoint> a = {cv::KeyPoint(40.f, 40.f, 31.f, 20.f)};
  const std::vector<cv::KeyPoint> b = {cv::KeyPoint(40.f, 40.f, 31.f, 110.f)};
  cv::Mat da(1, 32, CV_8UC1), db(1, 32, CV_8UC1);
  computeSteeredBrief(image, a, da, 0);
  computeSteeredBrief(rotated, b, db, 0);
  EXPECT_LE(descriptorDistance(da, 0, db, 0), 20);
  // Without steering, the descriptors of the rotated patch are unrelated.
  const std::vector<cv::KeyPoint> unsteered = {cv::KeyPoint(40.f, 40.f, 31.f, 20.f)};
  computeSteeredBrief(rotated, unsteered, db, 0);
  EXPECT_GT(descriptorDistance(da, 0, db, 0), 80);
}

TEST(SteeredBrief, DifferentPlacesGiveDifferentDescriptors) {
  const cv::Mat image = texture(200, 5);
  std::vector<cv::KeyPoint> kps;
  for (int i = 0; i < 20; ++i) kps.emplace_back(20.f + 8.f * i, 100.f, 31.f, 0.f);
  cv::Mat d(static_cast<int>(kps.size()), 32, CV_8UC1);
  computeSteeredBrief(image, kps, d, 0);
  for (int i = 0; i + 4 < d.rows; ++i) EXPECT_GT(descriptorDistance(d, i, d, i + 4), 60);
}

TEST(SteeredBrief, RejectsBadInput) {
  const cv::Mat image = texture(50, 1);
  cv::Mat d(1, 32, CV_8UC1);
  const std::vector<cv::KeyPoint> near_border = {cv::KeyPoint(10.f, 25.f, 31.f, 0.f)};
  EXPECT_THROW(computeSteeredBrief(image, near_border, d, 0), std::invalid_argument);
  const std::vector<cv::KeyPoint> ok = {cv::KeyPoint(25.f, 25.f, 31.f, 0.f)};
  EXPECT_THROW(computeSteeredBrief(image, ok, d, 1), std::invalid_argument);
  cv::Mat wrong(1, 16, CV_8UC1);
  EXPECT_THROW(computeSteeredBrief(image, ok, wrong, 0), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
