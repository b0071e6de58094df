#include "eval/kitti_metric.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "eval/eval_error.h"
#include "synthetic_trajectories.h"

namespace edgeslam {
namespace {

// Straight drive along z (KITTI's forward axis), 0.37 m per frame: no segment length is a whole
// number of frames, so the devkit's "first frame beyond d_first + L" is unambiguous.
constexpr double kSpacing = 0.37;
constexpr std::size_t kFrames = 2400;  // 887.6 m

Trajectory straightDrive() {
  Trajectory t;
  for (std::size_t i = 0; i < kFrames; ++i) {
    t.push_back({0.1 * static_cast<double>(i),
                 SE3d(Eigen::Quaterniond::Identity(),
                      Eigen::Vector3d(0, 0, kSpacing * static_cast<double>(i)))});
  }
  return t;
}

// Frames from a segment's first to its last frame, and the number of segments of that length.
std::size_t framesSpanned(double length) {
  return static_cast<std::size_t>(length / kSpacing) + 1;
}
std::size_t segmentCount(double length) {
  std::size_t count = 0;
  for (std::size_t f = 0; f + framesSpanned(length) < kFrames; f += 10) ++count;
  return count;
}

// Overall average of a per-segment value that depends only on the length, as the devkit takes it
// (mean over all segments).
template <typename PerLength>
double expectedAverage(PerLength value) {
  double sum = 0.0;
  std::size_t count = 0;
  for (int length = 100; length <= 800; length += 100) {
    sum += static_cast<double>(segmentCount(length)) * value(length);
    count += segmentCount(length);
  }
  return sum / static_cast<double>(count);
}

TEST(KittiMetric, IdenticalTrajectoriesHaveNoError) {
  const Trajectory gt = straightDrive();
  const KittiResult r = computeKittiMetric(test::pairsOf(gt, gt));
  EXPECT_EQ(r.t_rel_percent, 0.0);
  EXPECT_EQ(r.r_rel_deg_per_100m, 0.0);
  EXPECT_EQ(r.per_length.size(), 8U);
  EXPECT_NEAR(r.path_length_m, kSpacing * (kFrames - 1), 1e-6);
}

TEST(KittiMetric, SegmentsFollowDevkitRule) {
  const Trajectory gt = straightDrive();
  const KittiResult r = computeKittiMetric(test::pairsOf(gt, gt));
  std::size_t total = 0;
  for (const KittiLengthError& l : r.per_length) {
    EXPECT_EQ(l.segments, segmentCount(l.length_m)) << l.length_m;
    total += l.segments;
  }
  EXPECT_EQ(r.segments.size(), total);
  // The first 100 m segment ends at the first frame strictly more than 100 m on.
  EXPECT_EQ(r.segments.front().first_frame, 0U);
  EXPECT_EQ(r.segments.front().last_frame, framesSpanned(100));
  EXPECT_EQ(r.segments[8].first_frame, 10U);
}

TEST(KittiMetric, TranslationsScaledByOnePercentGiveOnePercent) {
  const Trajectory gt = straightDrive();
  Trajectory est = gt;
  for (StampedPose& p : est) p.pose.setTranslation(1.01 * p.pose.translation());
  const KittiResult r = computeKittiMetric(test::pairsOf(gt, est));
  // Error 1 % of the distance actually covered, divided by the nominal length.
  const auto per_length = [](double length) {
    return 1.0 * kSpacing * static_cast<double>(framesSpanned(length)) / length;
  };
  EXPECT_NEAR(r.t_rel_percent, expectedAverage(per_length), 1e-9);
  EXPECT_NEAR(r.t_rel_percent, 1.00, 0.005);
  EXPECT_NEAR(r.r_rel_deg_per_100m, 0.0, 1e-9);
  for (const KittiLengthError& l : r.per_length) {
    EXPECT_NEAR(l.t_rel_percent, per_length(l.length_m), 1e-9) << l.length_m;
  }
}

TEST(KittiMetric, ConstantYawDriftGivesItsRate) {
  const double drift = 1e-4;  // rad per metre travelled
  const Trajectory gt = straightDrive();
  Trajectory est = gt;
  for (StampedPose& p : est) {
    p.pose = test::yaw(drift * p.pose.translation().z(), p.pose.translation());
  }
  const KittiResult r = computeKittiMetric(test::pairsOf(gt, est));
  const double to_deg_per_100m = 180.0 / std::numbers::pi * 100.0;
  const auto per_length = [&](double length) {
    return drift * kSpacing * static_cast<double>(framesSpanned(length)) / length * to_deg_per_100m;
  };
  EXPECT_NEAR(r.r_rel_deg_per_100m, expectedAverage(per_length), 1e-6);
  EXPECT_NEAR(r.r_rel_deg_per_100m, drift * to_deg_per_100m, 0.01);
  for (const KittiLengthError& l : r.per_length) {
    EXPECT_NEAR(l.r_rel_deg_per_100m, per_length(l.length_m), 1e-6) << l.length_m;
  }
}

TEST(KittiMetric, Sim3RemovesAGlobalScale) {
  const Trajectory gt = straightDrive();
  Trajectory est = gt;
  for (StampedPose& p : est) p.pose.setTranslation(0.25 * p.pose.translation());
  KittiOptions options;
  options.align = AlignMode::kSim3;
  const KittiResult r = computeKittiMetric(test::pairsOf(gt, est), options);
  EXPECT_NEAR(r.scale, 4.0, 1e-9);
  EXPECT_NEAR(r.t_rel_percent, 0.0, 1e-9);
  EXPECT_NEAR(computeKittiMetric(test::pairsOf(gt, est)).t_rel_percent, 75.0, 1.0);
}

TEST(KittiMetric, TooShortPathThrows) {
  Trajectory gt = straightDrive();
  gt.resize(200);  // 73.6 m
  EXPECT_THROW(computeKittiMetric(test::pairsOf(gt, gt)), EvalError);
}

}  // namespace
}  // namespace edgeslam
