#include "features/fast_grid_detector.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <stdexcept>

namespace edgeslam {
namespace {

// A flat image with bright single-pixel dots: each is a FAST corner (all 16 circle pixels darker)
// whose score is about its contrast, with no equal-scored neighbour to suppress it.
cv::Mat dotsImage() {
  cv::Mat image(100, 160, CV_8UC1, cv::Scalar(100));
  auto dot = [&](int x, int y, int contrast) {
    image.at<std::uint8_t>(y, x) = static_cast<std::uint8_t>(100 + contrast);
  };
  // Region (5, 5, 150x90) with 30 px cells: 5 x 3 cells; cell (c, r) starts at (5 + 30c, 5 + 30r).
  dot(12, 12, 80);   // strong, cell (0, 0)
  dot(26, 26, 12);   // weak, same cell: must stay unsearched at the low threshold
  dot(76, 46, 12);   // weak, cell (2, 1)
  dot(106, 46, 12);  // weak, cell (3, 1): a run of two empty cells with (2, 1)
  dot(136, 79, 12);  // weak, cell (4, 2)
  return image;
}

int countIn(const std::vector<cv::KeyPoint>& kps, const cv::Rect& area) {
  return static_cast<int>(std::count_if(kps.begin(), kps.end(), [&](const cv::KeyPoint& kp) {
    return area.contains(cv::Point(static_cast<int>(kp.pt.x), static_cast<int>(kp.pt.y)));
  }));
}

TEST(FastGridDetector, SearchesOnlyEmptyCellsAgainAtTheLowThreshold) {
  const cv::Mat image = dotsImage();
  std::vector<cv::KeyPoint> kps;
  detectFastInGrid(image, cv::Rect(5, 5, 150, 90), FastGridOptions{20, 7, 30}, kps);
  const cv::Rect strong(4, 4, 16, 16), weak_same_cell(18, 18, 16, 16);
  EXPECT_GT(countIn(kps, strong), 0);
  EXPECT_EQ(countIn(kps, weak_same_cell), 0);
  for (const cv::Rect weak :
       {cv::Rect(68, 38, 16, 16), cv::Rect(98, 38, 16, 16), cv::Rect(128, 71, 16, 16)}) {
    EXPECT_GT(countIn(kps, weak), 0) << weak;
  }
  for (const cv::KeyPoint& kp : kps) {
    EXPECT_EQ(kp.response >= 20.f, strong.contains(cv::Point(kp.pt))) << kp.pt;
    EXPECT_GE(kp.response, 7.f);
  }
  // Nothing outside the region, nothing twice.
  EXPECT_EQ(countIn(kps, cv::Rect(5, 5, 150, 90)), static_cast<int>(kps.size()));
  for (std::size_t i = 0; i < kps.size(); ++i) {
    for (std::size_t j = i + 1; j < kps.size(); ++j) EXPECT_NE(kps[i].pt, kps[j].pt);
  }
}

TEST(FastGridDetector, EqualThresholdsMeanASinglePass) {
  const cv::Mat image = dotsImage();
  std::vector<cv::KeyPoint> kps;
  detectFastInGrid(image, cv::Rect(5, 5, 150, 90), FastGridOptions{20, 20, 30}, kps);
  ASSERT_FALSE(kps.empty());
  for (const cv::KeyPoint& kp : kps) EXPECT_GE(kp.response, 20.f);
}

TEST(FastGridDetector, RejectsBadInput) {
  const cv::Mat image = dotsImage();
  std::vector<cv::KeyPoint> kps;
  EXPECT_THROW(detectFastInGrid(image, cv::Rect(2, 5, 150, 90), {}, kps), std::invalid_argument);
  EXPECT_THROW(detectFastInGrid(image, cv::Rect(5, 5, 155, 90), {}, kps), std::invalid_argument);
  EXPECT_THROW(detectFastInGrid(image, cv::Rect(5, 5, 150, 90), FastGridOptions{7, 20, 30}, kps),
               std::invalid_argument);
  cv::Mat colour(100, 160, CV_8UC3, cv::Scalar::all(0));
  EXPECT_THROW(detectFastInGrid(colour, cv::Rect(5, 5, 150, 90), {}, kps), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
