// Self-calibrating bundle adjustment: a synthetic turning camera whose images come from other
// intrinsics than the ones the map was built with.
#include "optimize/intrinsics_refinement.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "optimize/camera_projection.h"

namespace edgeslam {
namespace {

CameraIntrinsics intrinsics(double f, double k1, double k2 = 0.0) {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = f;
  in.cx = 320.0;
  in.cy = 240.0;
  in.distortion.k1 = k1;
  in.distortion.k2 = k2;
  in.baseline_m = 0.08;
  return in;
}

struct Scene {
  BundleAdjustmentProblem problem;
  std::vector<SE3d> true_poses;
};

// Keyframes along a curve that turns 50 degrees; points in front of the whole path. Each point is
// observed where the true camera sees it, at its raw (distorted) pixel plus noise; the stored
// keypoint is that pixel undistorted with `assumed`, as the map keeps them. Observations of every
// `depth_every`-th point also carry a depth (a virtual right coordinate).
Scene makeTurningScene(const PinholeCamera& truth, const PinholeCamera& assumed, double noise_px,
                       int depth_every = 0) {
  Scene scene;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, noise_px);
  const int keyframes = 16;
  for (int k = 0; k < keyframes; ++k) {
    const double a = (-25.0 + 50.0 * k / (keyframes - 1)) * M_PI / 180.0;
    const Eigen::Vector3d centre(0.25 * k, 0.05 * std::sin(k), 0.15 * k);
    const SE3d T_wc(Eigen::Quaterniond(Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY())), centre);
    scene.true_poses.push_back(T_wc.inverse());
    scene.problem.keyframes.push_back({static_cast<std::uint64_t>(k), T_wc.inverse(), k == 0});
  }
  std::uniform_real_distribution<double> ux(-8.0, 11.0), uy(-2.5, 2.5), uz(4.0, 14.0);
  const double bf = assumed.fx() * assumed.intrinsics().baseline_m;
  while (scene.problem.points.size() < 700) {
    // Drawn last coordinate first, the order this scene was tuned with (gcc evaluates call
    // arguments right to left, clang left to right): every compiler draws the same scene.
    const double z = uz(rng);
    const double y = uy(rng);
    const Eigen::Vector3d X(ux(rng), y, z);
    const std::size_t index = scene.problem.points.size();
    const bool with_depth = depth_every > 0 && index % static_cast<std::size_t>(depth_every) == 0;
    std::vector<BAObservation> seen;
    for (int k = 0; k < keyframes; ++k) {
      const Eigen::Vector3d pc = scene.true_poses[static_cast<std::size_t>(k)] * X;
      const auto raw = truth.projectDistorted(pc);
      if (!raw || raw->x() < 0 || raw->x() > 640 || raw->y() < 0 || raw->y() > 480) continue;
      BAObservation o;
      o.keyframe = static_cast<std::size_t>(k);
      o.point = index;
      const double noise_y = noise(rng);
      const Eigen::Vector2d pixel_noise(noise(rng), noise_y);
      o.pixel = assumed.undistort(*raw + pixel_noise);
      if (with_depth) o.right_u = o.pixel.x() - bf / pc.z();
      o.inv_sigma2 = 1.0;
      seen.push_back(o);
    }
    if (seen.size() < 3) continue;
    scene.problem.points.push_back({static_cast<std::uint64_t>(1000 + index), X, false});
    scene.problem.observations.insert(scene.problem.observations.end(), seen.begin(), seen.end());
  }
  scene.problem.camera = CameraProjection::fromCamera(assumed, bf);
  return scene;
}

TEST(IntrinsicsRefinement, RecoversFocalLengthAndRadialDistortion) {
  const PinholeCamera truth(intrinsics(480.0, 0.06));
  const PinholeCamera assumed(intrinsics(495.0, 0.0));  // 3 % off, no distortion
  const Scene scene = makeTurningScene(truth, assumed, 0.3);
  const IntrinsicsRefinementResult r = refineIntrinsics(scene.problem, assumed);
  ASSERT_TRUE(r.adopted) << r.reason;
  EXPECT_NEAR(r.intrinsics.fx, 480.0, 3.0);
  EXPECT_NEAR(r.intrinsics.fy, 480.0, 3.0);
  EXPECT_NEAR(r.intrinsics.distortion.k1, 0.06, 0.01);
  EXPECT_EQ(r.intrinsics.cx, 320.0);
  EXPECT_EQ(r.intrinsics.distortion.k2, 0.0);  // not refined by default
  // Down to the noise (0.3 px per component).
  EXPECT_LT(r.rms_after, 0.35);
  EXPECT_GT(r.rms_before, 1.5 * r.rms_after);
  ASSERT_EQ(r.T_cw.size(), scene.problem.keyframes.size());
  ASSERT_EQ(r.points.size(), scene.problem.points.size());
  EXPECT_EQ(r.outliers, 0u);
}

TEST(IntrinsicsRefinement, StartsFromTheAssumedDistortion) {
  // The map's keypoints were undistorted with k1 = 0.02; the images have 0.06.
  const PinholeCamera truth(intrinsics(480.0, 0.06));
  const PinholeCamera assumed(intrinsics(480.0, 0.02));
  const Scene scene = makeTurningScene(truth, assumed, 0.3);
  IntrinsicsRefinementOptions options;
  options.refine_focal = false;
  const IntrinsicsRefinementResult r = refineIntrinsics(scene.problem, assumed, options);
  ASSERT_TRUE(r.adopted) << r.reason;
  EXPECT_EQ(r.intrinsics.fx, 480.0);
  EXPECT_NEAR(r.intrinsics.distortion.k1, 0.06, 0.01);
}

TEST(IntrinsicsRefinement, StrongGivenDistortionIsNoObstacle) {
  // A lens like TUM fr2's (k2 = -0.78): the bounds apply to the change, not to the values.
  const PinholeCamera truth(intrinsics(480.0, 0.26, -0.78));
  const PinholeCamera assumed(intrinsics(480.0, 0.23, -0.78));
  const Scene scene = makeTurningScene(truth, assumed, 0.3);
  IntrinsicsRefinementOptions options;
  options.refine_focal = false;
  const IntrinsicsRefinementResult r = refineIntrinsics(scene.problem, assumed, options);
  ASSERT_TRUE(r.adopted) << r.reason;
  EXPECT_NEAR(r.intrinsics.distortion.k1, 0.26, 0.01);
  EXPECT_EQ(r.intrinsics.distortion.k2, -0.78);
}

TEST(IntrinsicsRefinement, CorrectIntrinsicsAreKept) {
  const PinholeCamera truth(intrinsics(480.0, 0.03));
  const Scene scene = makeTurningScene(truth, truth, 0.3);
  const IntrinsicsRefinementResult r = refineIntrinsics(scene.problem, truth);
  EXPECT_FALSE(r.adopted);
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.intrinsics.fx, 480.0);
  EXPECT_EQ(r.intrinsics.distortion.k1, 0.03);
  // The poses are the fixed-intrinsics solve's: still the true ones up to noise.
  ASSERT_EQ(r.T_cw.size(), scene.true_poses.size());
  for (std::size_t k = 1; k < r.T_cw.size(); ++k) {
    EXPECT_LT(
        (r.T_cw[k].inverse().translation() - scene.true_poses[k].inverse().translation()).norm(),
        0.05)
        << "keyframe " << k;
  }
}

TEST(IntrinsicsRefinement, DepthObservationsScaleWithTheFocalLength) {
  const PinholeCamera truth(intrinsics(480.0, 0.0));
  const PinholeCamera assumed(intrinsics(470.0, 0.0));
  const Scene scene = makeTurningScene(truth, assumed, 0.3, /*depth_every=*/2);
  IntrinsicsRefinementOptions options;
  options.refine_k1 = false;
  const IntrinsicsRefinementResult r = refineIntrinsics(scene.problem, assumed, options);
  ASSERT_TRUE(r.adopted) << r.reason;
  EXPECT_NEAR(r.intrinsics.fx, 480.0, 2.0);
  EXPECT_LT(r.rms_after, 0.35);
}

TEST(IntrinsicsRefinement, ImplausibleChangesAreRefused) {
  const PinholeCamera truth(intrinsics(480.0, 0.0));
  const PinholeCamera assumed(intrinsics(540.0, 0.0));  // 12 % off: beyond the default 8 %
  const Scene scene = makeTurningScene(truth, assumed, 0.3);
  IntrinsicsRefinementOptions options;
  options.refine_k1 = false;
  const IntrinsicsRefinementResult r = refineIntrinsics(scene.problem, assumed, options);
  EXPECT_FALSE(r.adopted);
  EXPECT_NE(r.reason.find("focal"), std::string::npos) << r.reason;
  EXPECT_EQ(r.intrinsics.fx, 540.0);
  EXPECT_NEAR(r.estimate.fx, 480.0, 3.0);  // what the data asked for is still reported
}

TEST(IntrinsicsRefinement, TooFewKeyframesAreLeftAlone) {
  const PinholeCamera truth(intrinsics(480.0, 0.06));
  const PinholeCamera assumed(intrinsics(495.0, 0.0));
  Scene scene = makeTurningScene(truth, assumed, 0.3);
  for (std::size_t k = 4; k < scene.problem.keyframes.size(); ++k) {
    scene.problem.keyframes[k].fixed = true;
  }
  const IntrinsicsRefinementResult r = refineIntrinsics(scene.problem, assumed);
  EXPECT_FALSE(r.adopted);
  EXPECT_NE(r.reason.find("too few keyframes (3)"), std::string::npos) << r.reason;
  EXPECT_EQ(r.intrinsics.fx, 495.0);
  EXPECT_EQ(r.T_cw.size(), scene.problem.keyframes.size());
}

TEST(IntrinsicsRefinement, NothingToRefineOrMalformedProblemsThrow) {
  const PinholeCamera camera(intrinsics(480.0, 0.0));
  Scene scene = makeTurningScene(camera, camera, 0.0);
  IntrinsicsRefinementOptions nothing;
  nothing.refine_focal = nothing.refine_k1 = nothing.refine_k2 = false;
  EXPECT_THROW(refineIntrinsics(scene.problem, camera, nothing), std::invalid_argument);
  scene.problem.observations.front().point = scene.problem.points.size();
  EXPECT_THROW(refineIntrinsics(scene.problem, camera), std::invalid_argument);
}

TEST(IntrinsicsRefinement, ParsesTheCommandLineSet) {
  const auto off = parseRefinedIntrinsics("off");
  ASSERT_TRUE(off);
  EXPECT_FALSE(refinesAnything(*off));
  const auto default_set = parseRefinedIntrinsics("focal,k1");
  ASSERT_TRUE(default_set);
  EXPECT_TRUE(default_set->refine_focal);
  EXPECT_TRUE(default_set->refine_k1);
  EXPECT_FALSE(default_set->refine_k2);
  const auto k2 = parseRefinedIntrinsics("k2");
  ASSERT_TRUE(k2);
  EXPECT_TRUE(k2->refine_k2);
  EXPECT_FALSE(k2->refine_focal);
  for (const char* bad : {"", "fx", "focal,", "focal,focal", "off,k1", "K1"}) {
    EXPECT_FALSE(parseRefinedIntrinsics(bad)) << "'" << bad << "'";
  }
}

}  // namespace
}  // namespace edgeslam
