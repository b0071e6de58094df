#include "synth/ground_truth_masks.h"

#include <gtest/gtest.h>

#include "io/dataset_error.h"
#include "io/temp_folder.h"
#include "synth/mask_metrics.h"

namespace edgeslam {
namespace {

using test::TempFolder;

cv::Mat1b boxMask(cv::Rect box) {
  cv::Mat1b mask = cv::Mat1b::zeros(48, 64);
  mask(box).setTo(255);
  return mask;
}

TEST(GroundTruthMasks, AbsentWithoutMasksTxt) {
  TempFolder folder;
  EXPECT_FALSE(GroundTruthMasks::open(folder.path()).has_value());
  EXPECT_FALSE(loadGroundTruthMask(folder.path(), 0).has_value());
}

TEST(GroundTruthMasks, LoadsByIndexAndTimestamp) {
  TempFolder folder;
  test::writeImage(folder / "masks/000000.png", boxMask({0, 0, 10, 10}));
  test::writeImage(folder / "masks/000001.png", boxMask({20, 20, 5, 4}));
  test::writeText(folder / "masks.txt",
                  "# comment\n3.000000 masks/000000.png\n\n3.033333 masks/000001.png\n");
  const auto masks = GroundTruthMasks::open(folder.path());
  ASSERT_TRUE(masks.has_value());
  ASSERT_EQ(masks->size(), 2u);
  EXPECT_DOUBLE_EQ(masks->timestamps()[1], 3.033333);
  EXPECT_EQ(cv::countNonZero(masks->load(0)), 100);
  EXPECT_EQ(cv::countNonZero(masks->load(1)), 20);
  const auto at = masks->loadAt(3.0333335);
  ASSERT_TRUE(at.has_value());
  EXPECT_EQ(cv::countNonZero(*at), 20);
  EXPECT_FALSE(masks->loadAt(3.02).has_value());
  EXPECT_THROW(masks->load(2), DatasetError);
  const auto single = loadGroundTruthMask(folder.path(), 1);
  ASSERT_TRUE(single.has_value());
  EXPECT_EQ(cv::countNonZero(*single), 20);
  EXPECT_FALSE(loadGroundTruthMask(folder.path(), 5).has_value());
}

TEST(GroundTruthMasks, BadListsAndFilesNameTheProblem) {
  TempFolder folder;
  test::writeText(folder / "masks.txt", "0.0 masks/000000.png\nabc masks/000001.png\n");
  try {
    GroundTruthMasks::open(folder.path());
    FAIL();
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("masks.txt:2"), std::string::npos) << e.what();
  }
  test::writeText(folder / "masks.txt", "0.0\n");
  EXPECT_THROW(GroundTruthMasks::open(folder.path()), DatasetError);
  test::writeText(folder / "masks.txt", "0.0 masks/missing.png\n0.1 masks/colour.png\n");
  test::writeImage(folder / "masks/colour.png", cv::Mat3b(4, 4, cv::Vec3b(1, 2, 3)));
  const auto masks = GroundTruthMasks::open(folder.path());
  ASSERT_TRUE(masks.has_value());
  try {
    masks->load(0);
    FAIL();
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("missing.png"), std::string::npos) << e.what();
  }
  EXPECT_THROW(masks->load(1), DatasetError);
}

TEST(MaskMetrics, IntersectionOverUnion) {
  const cv::Mat1b a = boxMask({0, 0, 10, 10});
  const cv::Mat1b b = boxMask({5, 0, 10, 10});
  EXPECT_NEAR(*maskIoU(a, b), 50.0 / 150.0, 1e-12);
  EXPECT_DOUBLE_EQ(*maskIoU(a, a), 1.0);
  EXPECT_DOUBLE_EQ(*maskIoU(a, boxMask({30, 30, 5, 5})), 0.0);
  EXPECT_FALSE(maskIoU(cv::Mat1b::zeros(48, 64), cv::Mat1b::zeros(48, 64)).has_value());
  EXPECT_THROW(maskIoU(a, cv::Mat1b::zeros(10, 10)), std::invalid_argument);
}

TEST(MaskMetrics, FeaturesOnTheMask) {
  const cv::Mat1b mask = boxMask({0, 0, 10, 10});
  const FeaturesOnMask counts = countFeaturesOnMask(
      {{1.f, 1.f}, {9.4f, 9.4f}, {9.6f, 9.6f}, {30.f, 30.f}, {-5.f, 2.f}}, mask);
  EXPECT_EQ(counts.total, 4u);  // the point outside the image is not counted
  EXPECT_EQ(counts.on_mask, 2u);
  EXPECT_DOUBLE_EQ(*counts.share(), 0.5);
  EXPECT_FALSE(countFeaturesOnMask({}, mask).share().has_value());
}

}  // namespace
}  // namespace edgeslam
