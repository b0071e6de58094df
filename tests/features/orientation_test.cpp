#include "features/orientation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

float angleDifference(float a, float b) {
  float d = std::fmod(a - b + 540.f, 360.f) - 180.f;
  return std::abs(d);
}

TEST(IntensityCentroid, PointsTowardsTheBrightSide) {
  // Bright half-plane to the right of the centre: angle 0; below (y down): 90.
  cv::Mat right(41, 41, CV_8UC1, cv::Scalar(0));
  right.colRange(21, 41).setTo(200);
  const IntensityCentroid centroid;
  EXPECT_LT(angleDifference(centroid.angleAt(right, {20.f, 20.f}), 0.f), 1.f);
  cv::Mat below(41, 41, CV_8UC1, cv::Scalar(0));
  below.rowRange(21, 41).setTo(200);
  EXPECT_LT(angleDifference(centroid.angleAt(below, {20.f, 20.f}), 90.f), 1.f);
}

TEST(IntensityCentroid, FollowsARotatedImage) {
  cv::Mat image(61, 61, CV_8UC1);
  cv::RNG rng(3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 256);
  cv::GaussianBlur(image, image, cv::Size(9, 9), 3.0);
  const IntensityCentroid centroid;
  const float before = centroid.angleAt(image, {30.f, 30.f});
  cv::Mat rotated;
  cv::rotate(image, rotated, cv::ROTATE_90_CLOCKWISE);  // +90 degrees in image coordinates
  const float after = centroid.angleAt(rotated, {30.f, 30.f});
  EXPECT_LT(angleDifference(after, before + 90.f), 1.f);
}

TEST(IntensityCentroid, RejectsKeypointsNearTheBorder) {
  const cv::Mat image(40, 40, CV_8UC1, cv::Scalar(10));
  std::vector<cv::KeyPoint> kps = {cv::KeyPoint(5.f, 20.f, 7.f)};
  EXPECT_THROW(IntensityCentroid().compute(image, kps), std::invalid_argument);
  EXPECT_THROW(IntensityCentroid(0), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
