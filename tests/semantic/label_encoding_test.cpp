#include "semantic/label_encoding.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>

namespace edgeslam {
namespace {

// A 640x480 label image with three instances: two overlapping ellipses (people) and a box (car).
cv::Mat1b syntheticLabels() {
  cv::Mat1b labels = cv::Mat1b::zeros(480, 640);
  cv::rectangle(labels, cv::Rect(400, 250, 200, 120), cv::Scalar(3), cv::FILLED);
  cv::ellipse(labels, cv::Point(200, 260), cv::Size(55, 170), 0, 0, 360, cv::Scalar(2), cv::FILLED);
  cv::ellipse(labels, cv::Point(150, 240), cv::Size(50, 160), 5, 0, 360, cv::Scalar(1), cv::FILLED);
  return labels;
}

double labelIou(const cv::Mat1b& a, const cv::Mat1b& b) {
  const cv::Mat1b foreground = (a > 0) | (b > 0);
  const cv::Mat1b agree = (a == b) & foreground;
  return static_cast<double>(cv::countNonZero(agree)) / cv::countNonZero(foreground);
}

TEST(LabelEncoding, ExactRoundTripAtFullResolution) {
  const cv::Mat1b labels = syntheticLabels();
  std::string encoding;
  const auto bytes = encodeLabelImage(labels, 1, encoding);
  EXPECT_EQ(encoding, "png/1");
  const cv::Mat1b decoded = decodeLabelImage(bytes, encoding, labels.size());
  EXPECT_EQ(cv::countNonZero(decoded != labels), 0);
  // Far below the 300 kB of raw labels.
  EXPECT_LT(bytes.size(), 6000u);
}

TEST(LabelEncoding, DownscaledRoundTripKeepsTheInstances) {
  const cv::Mat1b labels = syntheticLabels();
  for (int downscale : {2, 4}) {
    std::string encoding;
    const auto bytes = encodeLabelImage(labels, downscale, encoding);
    EXPECT_EQ(encoding, "png/" + std::to_string(downscale));
    const cv::Mat1b decoded = decodeLabelImage(bytes, encoding, labels.size());
    ASSERT_EQ(decoded.size(), labels.size());
    const double iou = labelIou(decoded, labels);
    EXPECT_GT(iou, downscale == 2 ? 0.95 : 0.9) << "downscale " << downscale;
  }
  std::string full, half;
  EXPECT_LT(encodeLabelImage(labels, 2, half).size(), encodeLabelImage(labels, 1, full).size());
}

TEST(LabelEncoding, OddSizesRoundTrip) {
  cv::Mat1b labels = cv::Mat1b::zeros(371, 1227);
  cv::rectangle(labels, cv::Rect(1000, 100, 226, 270), cv::Scalar(7), cv::FILLED);
  std::string encoding;
  const auto bytes = encodeLabelImage(labels, 3, encoding);
  const cv::Mat1b decoded = decodeLabelImage(bytes, encoding, labels.size());
  EXPECT_GT(labelIou(decoded, labels), 0.95);
}

TEST(LabelEncoding, EmptyMaskCostsNoBytes) {
  std::string encoding;
  const auto bytes = encodeLabelImage(cv::Mat1b::zeros(480, 640), 2, encoding);
  EXPECT_EQ(encoding, "empty");
  EXPECT_TRUE(bytes.empty());
  const cv::Mat1b decoded = decodeLabelImage(bytes, encoding, cv::Size(640, 480));
  EXPECT_EQ(decoded.size(), cv::Size(640, 480));
  EXPECT_EQ(cv::countNonZero(decoded), 0);
}

TEST(LabelEncoding, RejectsBadInput) {
  std::string encoding;
  EXPECT_THROW(encodeLabelImage(cv::Mat1b(), 1, encoding), std::invalid_argument);
  EXPECT_THROW(encodeLabelImage(syntheticLabels(), 0, encoding), std::invalid_argument);
  const auto bytes = encodeLabelImage(syntheticLabels(), 2, encoding);
  EXPECT_THROW(decodeLabelImage(bytes, "jpeg/2", {640, 480}), std::invalid_argument);
  EXPECT_THROW(decodeLabelImage(bytes, "png/x", {640, 480}), std::invalid_argument);
  // Right bytes, wrong full size.
  EXPECT_THROW(decodeLabelImage(bytes, encoding, {1280, 960}), std::invalid_argument);
  EXPECT_THROW(decodeLabelImage({1, 2, 3}, encoding, {640, 480}), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
