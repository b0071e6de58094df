#include "geometry/sim3_scale.h"

#include <gtest/gtest.h>

#include <vector>

namespace edgeslam {
namespace {

Sim3Match matchAt(const Eigen::Vector3d& point1, const Eigen::Vector3d& point2) {
  Sim3Match m;
  m.point1 = point1;
  m.point2 = point2;
  m.pixel1 = m.pixel2 = Eigen::Vector2d::Zero();
  return m;
}

TEST(Sim3Scale, RangesFromTheSecondCameraGiveTheScaleDespiteAFewWrongMatches) {
  const Sim3d S_12(2.0, Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitY())),
                   Eigen::Vector3d(0.5, 0.0, 0.2));
  std::vector<Sim3Match> matches;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d point2(0.3 * i - 3.0, 0.1 * (i % 5), 4.0 + 0.5 * i);
    matches.push_back(matchAt(S_12 * point2, point2));
  }
  matches.push_back(matchAt({40.0, 0.0, 1.0}, {0.0, 0.0, 3.0}));  // wrong matches
  matches.push_back(matchAt({0.0, 0.0, 0.1}, {0.0, 0.0, 30.0}));
  const std::optional<double> scale = scaleFromRanges(S_12, matches);
  ASSERT_TRUE(scale);
  EXPECT_NEAR(*scale, 2.0, 1e-9);
}

TEST(Sim3Scale, BaselineIsMeasuredAgainstTheMedianRange) {
  const Eigen::Vector3d any = Eigen::Vector3d::UnitZ();
  const std::vector<Sim3Match> matches = {matchAt({0, 0, 9}, any), matchAt({0, 0, 10}, any),
                                          matchAt({0, 0, 50}, any)};
  const Sim3d apart(1.0, Eigen::Quaterniond::Identity(), Eigen::Vector3d(0.0, 0.0, 1.0));
  EXPECT_NEAR(*cameraBaselineOverRange(apart, matches), 0.1, 1e-12);
  EXPECT_FALSE(cameraBaselineOverRange(apart, {}));
  EXPECT_FALSE(scaleFromRanges(apart, {}));
}

}  // namespace
}  // namespace edgeslam
