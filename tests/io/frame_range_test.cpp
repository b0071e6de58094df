// `--frames A-B`: a stretch of a real dataset played as a sequence of its own.
#include "io/frame_range.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "support/shared_data.h"

namespace edgeslam {
namespace {

constexpr const char* kSevenScenes = "datasets/7scenes-redkitchen-1000";

TEST(FrameRange, PlaysTheStretchWithItsOwnTimestampsTruthAndImages) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  const auto folder = test::sharedPath(kSevenScenes);
  auto whole = openDataset(folder);
  const DatasetFrame original = whole->load(452);
  auto range = selectFrames(openDataset(folder), parseFrameRange("450-459"));
  ASSERT_EQ(range->info().frame_count, 10u);
  ASSERT_EQ(range->timestamps().size(), 10u);
  EXPECT_EQ(range->timestamps()[0], whole->timestamps()[450]);
  EXPECT_EQ(range->timestamps()[9], whole->timestamps()[459]);
  ASSERT_EQ(range->groundTruth().size(), 10u);
  ASSERT_TRUE(range->groundTruth()[2].has_value());
  EXPECT_TRUE(
      range->groundTruth()[2]->translation().isApprox(whole->groundTruth()[452]->translation()));
  EXPECT_TRUE(range->info().has_ground_truth);

  range->setContent({.color = false, .depth = true, .right = false});
  const DatasetFrame frame = range->load(2);
  EXPECT_EQ(frame.index, 2u);
  EXPECT_EQ(frame.name, original.name);
  EXPECT_EQ(frame.timestamp, original.timestamp);
  EXPECT_TRUE(frame.color.empty());  // the range's content choice reaches the real reader
  ASSERT_FALSE(frame.depth.empty());
  EXPECT_EQ(cv::norm(frame.gray, original.gray, cv::NORM_INF), 0.0);
  EXPECT_THROW((void)range->load(10), std::out_of_range);
}

TEST(FrameRange, RefusesARangeOutsideTheDataset) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  const auto folder = test::sharedPath(kSevenScenes);
  EXPECT_THROW((void)selectFrames(openDataset(folder), parseFrameRange("1000-1000")),
               std::invalid_argument);
  EXPECT_THROW((void)selectFrames(openDataset(folder), parseFrameRange("900-1000")),
               std::invalid_argument);
  auto all = selectFrames(openDataset(folder), parseFrameRange("0-999"));
  EXPECT_EQ(all->info().frame_count, 1000u);
}

// `--frames 0-200,375-999`: two stretches as one sequence, the camera kidnapped between them.
TEST(FrameRange, SeveralRangesPlayOneAfterTheOtherWithTimeGoingOn) {
  EDGESLAM_REQUIRE_SHARED(kSevenScenes);
  const auto folder = test::sharedPath(kSevenScenes);
  auto whole = openDataset(folder);
  auto cut = selectFrames(openDataset(folder), parseFrameRanges("100-109,500-504,20-21"));
  ASSERT_EQ(cut->info().frame_count, 17u);
  const std::vector<double>& t = cut->timestamps();
  EXPECT_EQ(t[0], whole->timestamps()[100]);
  EXPECT_EQ(t[9], whole->timestamps()[109]);
  const double interval = whole->timestamps()[1] - whole->timestamps()[0];
  for (std::size_t i = 1; i < t.size(); ++i) EXPECT_NEAR(t[i] - t[i - 1], interval, 1e-6) << i;
  ASSERT_TRUE(cut->groundTruth()[10].has_value());
  EXPECT_TRUE(
      cut->groundTruth()[10]->translation().isApprox(whole->groundTruth()[500]->translation()));
  EXPECT_TRUE(
      cut->groundTruth()[16]->translation().isApprox(whole->groundTruth()[21]->translation()));
  const DatasetFrame frame = cut->load(15);
  EXPECT_EQ(frame.name, whole->load(20).name);
  EXPECT_EQ(frame.timestamp, t[15]);
  EXPECT_THROW((void)selectFrames(openDataset(folder), parseFrameRanges("0-10,995-1000")),
               std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
