#include "optimize/local_bundle_adjustment.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

#include "bundle_scene.h"
#include "cpu_timer.h"

namespace edgeslam {
namespace {

using test::degToRad;
using test::radToDeg;

// The truth with the first two keyframes fixed (the gauge: position, orientation and scale) and
// every other pose and point perturbed.
BundleAdjustmentProblem perturbed(const BundleAdjustmentProblem& truth, std::mt19937& rng,
                                  double pose_m = 0.05, double pose_deg = 1.0,
                                  double point_m = 0.05) {
  BundleAdjustmentProblem p = truth;
  std::normal_distribution<double> n(0.0, point_m);
  for (std::size_t k = 0; k < p.keyframes.size(); ++k) {
    if (k < 2) {
      p.keyframes[k].fixed = true;
    } else {
      p.keyframes[k].T_cw = test::perturb(p.keyframes[k].T_cw, pose_m, degToRad(pose_deg), rng);
    }
  }
  for (BAPoint& point : p.points) point.position += Eigen::Vector3d(n(rng), n(rng), n(rng));
  return p;
}

struct Errors {
  double max_pose_m = 0.0, max_pose_deg = 0.0, max_point_m = 0.0;
};

Errors errorsAgainst(const BundleAdjustmentProblem& truth, const BundleAdjustmentResult& r) {
  Errors e;
  for (std::size_t k = 0; k < truth.keyframes.size(); ++k) {
    e.max_pose_m =
        std::max(e.max_pose_m, test::translationError(r.T_cw[k], truth.keyframes[k].T_cw));
    e.max_pose_deg =
        std::max(e.max_pose_deg, radToDeg(rotationDistance(r.T_cw[k], truth.keyframes[k].T_cw)));
  }
  for (std::size_t i = 0; i < truth.points.size(); ++i) {
    e.max_point_m = std::max(e.max_point_m, (r.points[i] - truth.points[i].position).norm());
  }
  return e;
}

TEST(BundleAdjustment, RecoversPerturbedPosesAndPointsWithFixedGauge) {
  std::mt19937 rng(20);
  const test::BundleScene scene = test::makeBundleScene(10, 600, rng, 0.0, /*stereo_every=*/3);
  const BundleAdjustmentProblem start = perturbed(scene.truth, rng);
  const BundleAdjustmentResult r = bundleAdjust(start);
  const Errors e = errorsAgainst(scene.truth, r);
  EXPECT_LT(e.max_pose_m, 1e-4);
  EXPECT_LT(e.max_pose_deg, 1e-3);
  EXPECT_LT(e.max_point_m, 1e-3);
  EXPECT_TRUE(r.outliers.empty());
  EXPECT_GT(r.rms_before, 5.0);
  EXPECT_LT(r.rms_after, 1e-3);
  EXPECT_FALSE(r.cancelled);
  for (int k = 0; k < 2; ++k) {  // fixed keyframes stay put
    EXPECT_EQ((r.T_cw[k].matrix() - start.keyframes[k].T_cw.matrix()).norm(), 0.0);
  }
}

TEST(BundleAdjustment, ReducesReprojectionErrorOnNoisyData) {
  std::mt19937 rng(21);
  const double noise = 0.5;
  const test::BundleScene scene = test::makeBundleScene(10, 800, rng, noise);
  const BundleAdjustmentProblem start = perturbed(scene.truth, rng, 0.03, 0.5, 0.03);
  const BundleAdjustmentResult r = bundleAdjust(start);
  EXPECT_GT(r.rms_before, 3.0);
  EXPECT_LT(r.rms_after, noise);  // fewer free parameters than residuals: below the noise
  EXPECT_GT(r.rms_after, 0.5 * noise);
  const Errors e = errorsAgainst(scene.truth, r);
  EXPECT_LT(e.max_pose_m, 0.01);
  EXPECT_LT(e.max_pose_deg, 0.1);
  EXPECT_LT(r.outliers.size(), start.observations.size() / 100);
}

TEST(BundleAdjustment, ReturnsCorruptedObservationsAsOutliers) {
  std::mt19937 rng(22);
  test::BundleScene scene = test::makeBundleScene(10, 500, rng, 0.0, 4);
  std::vector<std::size_t> corrupted;
  for (std::size_t i = 7; i < scene.truth.observations.size(); i += 41) {
    scene.truth.observations[i].pixel += Eigen::Vector2d(25.0, -30.0);
    if (scene.truth.observations[i].right_u) *scene.truth.observations[i].right_u += 25.0;
    corrupted.push_back(i);
  }
  // Also one observation of a point behind its keyframe.
  const BundleAdjustmentResult r = bundleAdjust(perturbed(scene.truth, rng, 0.02, 0.5, 0.02));
  EXPECT_EQ(r.outliers, corrupted);
  const Errors e = errorsAgainst(scene.truth, r);
  EXPECT_LT(e.max_pose_m, 1e-3);
}

TEST(BundleAdjustment, PresetCancelFlagReturnsTheInputUntouched) {
  std::mt19937 rng(23);
  const test::BundleScene scene = test::makeBundleScene(6, 200, rng);
  const BundleAdjustmentProblem start = perturbed(scene.truth, rng);
  std::atomic<bool> cancel{true};
  BundleAdjustmentOptions options;
  options.cancel = &cancel;
  const BundleAdjustmentResult r = bundleAdjust(start, options);
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.iterations, 0);
  for (std::size_t k = 0; k < start.keyframes.size(); ++k) {
    EXPECT_EQ((r.T_cw[k].matrix() - start.keyframes[k].T_cw.matrix()).norm(), 0.0);
  }
}

TEST(BundleAdjustment, CancelFlagStopsTheRunEarly) {
  std::mt19937 rng(24);
  const test::BundleScene scene = test::makeBundleScene(10, 500, rng);
  const BundleAdjustmentProblem start = perturbed(scene.truth, rng, 0.2, 5.0, 0.3);
  std::atomic<bool> cancel{false};
  BundleAdjustmentOptions options = BundleAdjustmentOptions::global();
  options.first_pass_iterations = 50;
  options.cancel = &cancel;
  // A new keyframe "arrives" during the second iteration.
  options.on_iteration = [&cancel](int iteration) {
    if (iteration == 2) cancel = true;
  };
  const BundleAdjustmentResult r = bundleAdjust(start, options);
  EXPECT_TRUE(r.cancelled);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_LT(r.rms_after, r.rms_before);  // the accepted steps are kept
}

TEST(BundleAdjustment, TimeBudgetStopsTheRun) {
  std::mt19937 rng(25);
  const test::BundleScene scene = test::makeBundleScene(10, 500, rng);
  BundleAdjustmentOptions options;
  options.max_time_s = 1e-6;
  const BundleAdjustmentResult r = bundleAdjust(perturbed(scene.truth, rng), options);
  EXPECT_TRUE(r.timed_out);
  EXPECT_LE(r.iterations, 1);
}

TEST(BundleAdjustment, GlobalBundleAdjustmentScalesToManyKeyframes) {
  // More free keyframes than the dense Schur limit: the sparse Schur path.
  std::mt19937 rng(26);
  const test::BundleScene scene = test::makeBundleScene(60, 3000, rng, 0.0, 5, 6);
  const BundleAdjustmentProblem start = perturbed(scene.truth, rng, 0.02, 0.3, 0.02);
  BundleAdjustmentOptions options = BundleAdjustmentOptions::global();
  options.first_pass_iterations = 20;
  const test::CpuTimer timer;
  const BundleAdjustmentResult r = bundleAdjust(start, options);
  std::printf(
      "global BA, %zu keyframes, %zu points, %zu observations: wall %.1f ms, thread CPU %.1f ms, "
      "%d iterations\n",
      start.keyframes.size(), start.points.size(), start.observations.size(), timer.wallMs(),
      timer.cpuMs(), r.iterations);
  const Errors e = errorsAgainst(scene.truth, r);
  EXPECT_LT(e.max_pose_m, 1e-3);
  EXPECT_LT(r.rms_after, 1e-2);
}

TEST(BundleAdjustment, RejectsBadInput) {
  std::mt19937 rng(27);
  test::BundleScene scene = test::makeBundleScene(4, 50, rng);
  BundleAdjustmentProblem bad = scene.truth;
  bad.observations[3].point = bad.points.size();
  EXPECT_THROW(bundleAdjust(bad), std::invalid_argument);
  bad = scene.truth;
  bad.observations[3].keyframe = 99;
  EXPECT_THROW(bundleAdjust(bad), std::invalid_argument);
  bad = scene.truth;
  bad.points[2].position.x() = std::nan("");
  EXPECT_THROW(bundleAdjust(bad), std::invalid_argument);
  bad = scene.truth;
  bad.observations[0].right_u = 10.0;
  bad.camera.bf = 0.0;
  EXPECT_THROW(bundleAdjust(bad), std::invalid_argument);
}

void timeLocalWindow(int stereo_every, const char* label) {
  std::mt19937 rng(28);
  const test::BundleScene scene = test::makeBundleScene(10, 2000, rng, 0.5, stereo_every);
  const BundleAdjustmentProblem start = perturbed(scene.truth, rng, 0.02, 0.5, 0.03);
  std::vector<double> wall_ms, cpu_ms;
  BundleAdjustmentResult r;
  for (int run = 0; run < 5; ++run) {
    const test::CpuTimer timer;
    r = bundleAdjust(start);
    wall_ms.push_back(timer.wallMs());
    cpu_ms.push_back(timer.cpuMs());
  }
  std::sort(wall_ms.begin(), wall_ms.end());
  std::sort(cpu_ms.begin(), cpu_ms.end());
  std::printf(
      "local BA, 10 keyframes (2 fixed), %zu points, %zu %s observations: median wall %.1f ms, "
      "median thread CPU %.1f ms, %d iterations, rms %.2f -> %.2f\n",
      start.points.size(), start.observations.size(), label, wall_ms[wall_ms.size() / 2],
      cpu_ms[cpu_ms.size() / 2], r.iterations, r.rms_before, r.rms_after);
  EXPECT_LT(r.rms_after, 0.6);
}

TEST(BundleAdjustment, TimingLocalWindow10KeyframesAnd2000PointsMono) {
  timeLocalWindow(0, "mono");
}

TEST(BundleAdjustment, TimingLocalWindow10KeyframesAnd2000PointsStereo) {
  timeLocalWindow(1, "stereo");
}

}  // namespace
}  // namespace edgeslam
