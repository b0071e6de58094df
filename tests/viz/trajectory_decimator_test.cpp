#include "viz/trajectory_decimator.h"

#include <gtest/gtest.h>

namespace edgeslam::viz {
namespace {

TEST(VizTrajectoryDecimator, KeepsEverythingBelowCapacity) {
  TrajectoryDecimator decimator(10);
  for (int i = 0; i < 10; ++i) decimator.add({double(i), 0, 0});
  ASSERT_EQ(decimator.positions().size(), 10u);
  EXPECT_EQ(decimator.stride(), 1u);
  EXPECT_EQ(decimator.positions()[9].x(), 9.0);
}

TEST(VizTrajectoryDecimator, StaysBoundedAndEvenlySpaced) {
  TrajectoryDecimator decimator(100);
  const int offered = 100000;
  for (int i = 0; i < offered; ++i) decimator.add({double(i), 0, 0});
  const auto& kept = decimator.positions();
  EXPECT_LE(kept.size(), 100u);
  EXPECT_GE(kept.size(), 50u);
  // The whole path stays: the first point, and points up to the last stride.
  EXPECT_EQ(kept.front().x(), 0.0);
  EXPECT_GT(kept.back().x(), offered - 1 - static_cast<double>(decimator.stride()));
  for (std::size_t i = 1; i < kept.size(); ++i) {
    EXPECT_EQ(kept[i].x() - kept[i - 1].x(), static_cast<double>(decimator.stride())) << i;
  }
}

}  // namespace
}  // namespace edgeslam::viz
