#include "semantic/feature_subset.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "map/synthetic_views.h"
#include "semantic/keyframe_image.h"

namespace edgeslam {
namespace {

FrameFeatures rowOfFeatures(int n, bool with_depth) {
  FrameFeatures f;
  f.descriptors.create(n, 32, CV_8U);
  for (int i = 0; i < n; ++i) {
    f.keypoints.emplace_back(cv::Point2f(20.f + 10.f * i, 100.f), 31.f, 0.f, 1.f, i % 3);
    f.descriptors.row(i).setTo(i);
    if (with_depth) {
      f.depth.push_back(1.f + 0.1f * i);
      f.right_u.push_back(5.f * i);
    }
  }
  f.bf = 40.f;
  return f;
}

TEST(SelectFeatures, KeepsTheListedKeypointsWithTheirDescriptorsDepthAndGrid) {
  const FrameFeatures all = rowOfFeatures(10, true);
  const auto kept = selectFeatures(all, {1, 4, 9}, test::syntheticCamera());
  ASSERT_EQ(kept->size(), 3u);
  EXPECT_EQ(kept->keypoints[1].pt, all.keypoints[4].pt);
  EXPECT_EQ(kept->keypoints[2].octave, all.keypoints[9].octave);
  EXPECT_EQ(kept->descriptors.at<std::uint8_t>(2, 5), 9);
  EXPECT_FLOAT_EQ(kept->depth[0], all.depth[1]);
  EXPECT_FLOAT_EQ(kept->right_u[2], all.right_u[9]);
  EXPECT_FLOAT_EQ(kept->bf, 40.f);
  // The grid indexes the subset: the keypoint at x = 60 (all[4]) is index 1 here.
  EXPECT_EQ(kept->grid.featuresInArea(60.f, 100.f, 2.f), std::vector<int>{1});
}

TEST(SelectFeatures, NoDepthStaysNoDepthAndBadIndicesThrow) {
  const FrameFeatures all = rowOfFeatures(4, false);
  const auto kept = selectFeatures(all, {0, 3}, test::syntheticCamera());
  EXPECT_TRUE(kept->depth.empty());
  EXPECT_FALSE(kept->hasDepth(0));
  EXPECT_THROW(selectFeatures(all, {0, 4}, test::syntheticCamera()), std::out_of_range);
  EXPECT_EQ(selectFeatures(all, {}, test::syntheticCamera())->size(), 0u);
}

TEST(KeyFrameImage, IsReducedAndJpegCodedAndTheRawImageDropped) {
  KeyFrameUpload upload;
  upload.raw_image = cv::Mat(480, 640, CV_8UC3, cv::Scalar(10, 200, 30));
  compressKeyFrameImage(upload, {2, 80});
  EXPECT_TRUE(upload.raw_image.empty());
  EXPECT_EQ(upload.image_encoding, "jpeg");
  ASSERT_GT(upload.image_bytes.size(), 100u);
  EXPECT_LT(upload.image_bytes.size(), 20000u);
  // JPEG magic, and nothing to do the second time.
  EXPECT_EQ(upload.image_bytes[0], 0xFF);
  EXPECT_EQ(upload.image_bytes[1], 0xD8);
  const auto bytes = upload.image_bytes;
  compressKeyFrameImage(upload);
  EXPECT_EQ(upload.image_bytes, bytes);
}

TEST(KeyFrameImage, RejectsOtherImageTypesAndBadOptions) {
  KeyFrameUpload upload;
  upload.raw_image = cv::Mat(48, 64, CV_32F, cv::Scalar(1));
  EXPECT_THROW(compressKeyFrameImage(upload), std::invalid_argument);
  upload.raw_image = cv::Mat(48, 64, CV_8U, cv::Scalar(1));
  EXPECT_THROW(compressKeyFrameImage(upload, {0, 80}), std::invalid_argument);
  EXPECT_THROW(compressKeyFrameImage(upload, {1, 101}), std::invalid_argument);
  compressKeyFrameImage(upload, {1, 90});
  EXPECT_EQ(upload.image_encoding, "jpeg");
}

}  // namespace
}  // namespace edgeslam
