#include <gtest/gtest.h>

#include "semantic/centernet_detector.h"
#include "semantic/segmentation.h"

namespace edgeslam {
namespace {

TEST(ClassAwareNms, DropsOverlapsAboveTheThresholdWithinAClass) {
  const std::vector<Detection> detections = {
      {0, 0.6f, cv::Rect2f(0, 0, 100, 100)},
      {0, 0.9f, cv::Rect2f(10, 0, 100, 100)},  // IoU 0.82 with the first
      {0, 0.5f, cv::Rect2f(30, 0, 100, 100)},  // IoU 0.54 with the first, 0.67 with the second
      {2, 0.4f, cv::Rect2f(10, 0, 100, 100)},  // other class: never suppressed by a person
      {0, 0.3f, cv::Rect2f(400, 400, 50, 50)}};
  const auto strict = classAwareNms(detections, 0.6f);
  ASSERT_EQ(strict.size(), 3u);
  EXPECT_FLOAT_EQ(strict[0].score, 0.9f);
  EXPECT_EQ(strict[1].class_id, 2);
  EXPECT_FLOAT_EQ(strict[2].score, 0.3f);
  const auto lenient = classAwareNms(detections, 0.8f);
  ASSERT_EQ(lenient.size(), 4u);  // only the 0.82 overlap goes
  EXPECT_FLOAT_EQ(lenient[1].score, 0.5f);
}

TEST(AssembleSegmentation, PixelMasksWinOverBoxesThenScores) {
  const cv::Size size(100, 80);
  auto instance = [&](float score, cv::Rect box, bool is_box) {
    SegmentedInstance out;
    out.class_id = is_box ? 5 : 0;
    out.score = score;
    out.box = box;
    out.mask = cv::Mat1b::zeros(size);
    out.mask(box).setTo(255);
    out.mask_is_box = is_box;
    return out;
  };
  const Segmentation s = assembleSegmentation(
      {instance(0.5f, {10, 10, 30, 30}, false), instance(0.9f, {0, 0, 60, 60}, true),
       instance(0.7f, {30, 30, 30, 30}, false)},
      size);
  ASSERT_EQ(s.instances.size(), 3u);
  EXPECT_FLOAT_EQ(s.instances[0].score, 0.9f);  // sorted by score
  EXPECT_EQ(s.label_image(5, 5), 1);            // box only
  EXPECT_EQ(s.label_image(15, 15), 3);          // person (0.5) over the box (0.9)
  EXPECT_EQ(s.label_image(35, 35), 2);          // 0.7 over 0.5
  EXPECT_EQ(s.label_image(70, 90), 0);
  EXPECT_EQ(cv::countNonZero(s.movable_mask != ((s.label_image > 0) & 255)), 0);
}

TEST(AssembleSegmentation, LabelsCapAt255) {
  std::vector<SegmentedInstance> many(300);
  for (auto& instance : many) {
    instance.mask = cv::Mat1b::zeros(4, 4);
    instance.mask(0, 0) = 255;
  }
  const Segmentation s = assembleSegmentation(std::move(many), {4, 4});
  EXPECT_EQ(s.instances.size(), 300u);
  EXPECT_EQ(instanceLabel(299), 255);
  EXPECT_EQ(s.label_image(0, 0), 1);
}

}  // namespace
}  // namespace edgeslam
