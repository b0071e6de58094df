// The pair triangulation shared by local mapping and the client: a known scene seen from two
// keyframes gives its points back, and pairs without parallax, behind the cameras, off the
// epipolar geometry or at inconsistent scales are refused.
#include "map/pair_triangulation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

using test::poseAt;

// Two keyframes each with one keypoint per given pixel.
struct PairOfKeyFrames {
  PinholeCamera camera = test::syntheticCamera();
  Map map;
  KeyFrame* kf1 = nullptr;
  KeyFrame* kf2 = nullptr;

  PairOfKeyFrames(const SE3d& T1, const Eigen::Vector2d& px1, int octave1, const SE3d& T2,
                  const Eigen::Vector2d& px2, int octave2) {
    kf1 = map.createKeyFrame(0, 0.0, features(px1, octave1), T1);
    kf2 = map.createKeyFrame(1, 0.1, features(px2, octave2), T2);
  }

  std::shared_ptr<FrameFeatures> features(const Eigen::Vector2d& px, int octave) const {
    auto f = std::make_shared<FrameFeatures>();
    f->keypoints.emplace_back(static_cast<float>(px.x()), static_cast<float>(px.y()), 31.f, 0.f,
                              0.f, octave);
    f->descriptors = cv::Mat::zeros(1, 32, CV_8UC1);
    f->grid = FeatureGrid(camera.undistortedBounds(), f->keypoints);
    return f;
  }

  PairTriangulation triangulate() const {
    return triangulateKeypointPair(*kf1, 0, *kf2, 0, camera);
  }
};

Eigen::Vector2d pixelOf(const PinholeCamera& camera, const SE3d& T_cw, const Eigen::Vector3d& x) {
  // The pinhole projection, also for points behind the camera.
  const Eigen::Vector3d pc = T_cw * x;
  return {camera.fx() * pc.x() / pc.z() + camera.cx(), camera.fy() * pc.y() / pc.z() + camera.cy()};
}

TEST(PairTriangulation, SceneSeenFromTwoKeyFramesComesBack) {
  test::SyntheticScene scene(300, 5);
  Map map;
  MutexLock lock(map.updateMutex());
  const auto v1 = scene.view(poseAt({0, 0, 0}), 0, false);
  const auto v2 = scene.view(poseAt({0.3, 0.05, 0}, 0.05), 0, false);
  KeyFrame* kf1 = scene.addKeyFrame(map, v1, 0, false);
  KeyFrame* kf2 = scene.addKeyFrame(map, v2, 1, false);
  std::size_t pairs = 0, accepted = 0;
  std::vector<double> errors;
  for (std::size_t i1 = 0; i1 < v1.scene_point.size(); ++i1) {
    for (std::size_t i2 = 0; i2 < v2.scene_point.size(); ++i2) {
      if (v1.scene_point[i1] != v2.scene_point[i2]) continue;
      ++pairs;
      const PairTriangulation t = triangulateKeypointPair(*kf1, i1, *kf2, i2, scene.camera());
      if (!t.position) continue;
      ++accepted;
      EXPECT_EQ(t.rejection, PairRejection::kNone);
      // 0.3 px noise over a 0.3 m baseline at 2-4 m: depth within ~5 cm (1 sigma at 4 m).
      const Eigen::Vector3d& truth = scene.points()[static_cast<std::size_t>(v1.scene_point[i1])];
      errors.push_back((*t.position - truth).norm());
      EXPECT_LT(errors.back(), 0.2) << "pair " << i1 << "/" << i2;
      EXPECT_EQ(triangulateMatchedPair(*kf1, i1, *kf2, i2, scene.camera()), t.position);
    }
  }
  ASSERT_GT(pairs, 100u);
  EXPECT_GE(accepted * 100, pairs * 98);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  EXPECT_LT(errors[errors.size() / 2], 0.03);
}

TEST(PairTriangulation, KnownPointFromTwoCameras) {
  const Eigen::Vector3d x(0.2, -0.1, 3.0);
  const SE3d T1 = poseAt({0, 0, 0});
  const SE3d T2 = poseAt({0.4, 0, 0.1});
  const PinholeCamera camera = test::syntheticCamera();
  const PairOfKeyFrames pair(T1, pixelOf(camera, T1, x), 0, T2, pixelOf(camera, T2, x), 0);
  const PairTriangulation t = pair.triangulate();
  ASSERT_TRUE(t.position.has_value()) << toString(t.rejection);
  EXPECT_LT((*t.position - x).norm(), 1e-4);
}

TEST(PairTriangulation, NoParallaxIsRefused) {
  const Eigen::Vector3d x(0.2, -0.1, 3.0);
  const SE3d T1 = poseAt({0, 0, 0});
  const SE3d T2 = poseAt({0.01, 0, 0});  // 0.2 degrees at 3 m
  const PinholeCamera camera = test::syntheticCamera();
  const PairOfKeyFrames pair(T1, pixelOf(camera, T1, x), 0, T2, pixelOf(camera, T2, x), 0);
  const PairTriangulation t = pair.triangulate();
  EXPECT_FALSE(t.position.has_value());
  EXPECT_EQ(t.rejection, PairRejection::kTooLittleParallax);
}

TEST(PairTriangulation, RaysUnderTheMinimumParallaxAreRefused) {
  const Eigen::Vector3d x(0.0, 0.0, 3.0);
  const SE3d T1 = poseAt({0, 0, 0});
  const SE3d T2 = poseAt({0.07, 0, 0});  // 1.34 degrees at 3 m: above ORB-SLAM2's 1.15
  const PinholeCamera camera = test::syntheticCamera();
  const PairOfKeyFrames pair(T1, pixelOf(camera, T1, x), 0, T2, pixelOf(camera, T2, x), 0);
  ASSERT_GT(kDefaultMinTriangulationParallaxDeg, 1.34);
  const PairTriangulation refused = triangulateKeypointPair(*pair.kf1, 0, *pair.kf2, 0, camera);
  EXPECT_FALSE(refused.position.has_value());
  EXPECT_EQ(refused.rejection, PairRejection::kTooLittleParallax);
  const PairTriangulation accepted =
      triangulateKeypointPair(*pair.kf1, 0, *pair.kf2, 0, camera, /*min_parallax_deg=*/1.2);
  ASSERT_TRUE(accepted.position.has_value()) << toString(accepted.rejection);
  EXPECT_LT((*accepted.position - x).norm(), 1e-4);
}

TEST(PairTriangulation, PointBehindTheCamerasIsRefused) {
  // Both keypoints are where a point 3 m behind both cameras projects: the rays, followed
  // forwards, diverge.
  const Eigen::Vector3d x(0.1, 0.05, -3.0);
  const SE3d T1 = poseAt({0, 0, 0});
  const SE3d T2 = poseAt({0.3, 0, 0});
  const PinholeCamera camera = test::syntheticCamera();
  const PairOfKeyFrames pair(T1, pixelOf(camera, T1, x), 0, T2, pixelOf(camera, T2, x), 0);
  const PairTriangulation t = pair.triangulate();
  EXPECT_FALSE(t.position.has_value());
  EXPECT_EQ(t.rejection, PairRejection::kBehindCamera);
}

TEST(PairTriangulation, PairOffTheEpipolarLineIsRefused) {
  const Eigen::Vector3d x(0.2, -0.1, 3.0);
  const SE3d T1 = poseAt({0, 0, 0});
  const SE3d T2 = poseAt({0.4, 0, 0});
  const PinholeCamera camera = test::syntheticCamera();
  // A horizontal baseline: 12 px of vertical disparity fits no point.
  const PairOfKeyFrames pair(T1, pixelOf(camera, T1, x), 0, T2,
                             pixelOf(camera, T2, x) + Eigen::Vector2d(0, 12), 0);
  const PairTriangulation t = pair.triangulate();
  EXPECT_FALSE(t.position.has_value());
  EXPECT_EQ(t.rejection, PairRejection::kReprojection);
}

TEST(PairTriangulation, InconsistentScalesAreRefused) {
  // Both cameras about 3 m from the point, but one keypoint found 7 pyramid levels (3.6 times)
  // coarser than the other: not the same physical detail.
  const Eigen::Vector3d x(0.2, -0.1, 3.0);
  const SE3d T1 = poseAt({0, 0, 0});
  const SE3d T2 = poseAt({0.4, 0, 0});
  const PinholeCamera camera = test::syntheticCamera();
  const PairOfKeyFrames consistent(T1, pixelOf(camera, T1, x), 1, T2, pixelOf(camera, T2, x), 1);
  EXPECT_TRUE(consistent.triangulate().position.has_value());
  const PairOfKeyFrames pair(T1, pixelOf(camera, T1, x), 0, T2, pixelOf(camera, T2, x), 7);
  const PairTriangulation t = pair.triangulate();
  EXPECT_FALSE(t.position.has_value());
  EXPECT_EQ(t.rejection, PairRejection::kScaleInconsistent);
}

TEST(PairTriangulation, DepthStandsInForMissingParallax) {
  // RGB-D: with almost no baseline the keypoint's depth gives the point.
  test::SyntheticScene scene(100, 9);
  Map map;
  MutexLock lock(map.updateMutex());
  const auto v1 = scene.view(poseAt({0, 0, 0}), 0, true);
  const auto v2 = scene.view(poseAt({0, 0, 0.005}), 0, true);
  KeyFrame* kf1 = scene.addKeyFrame(map, v1, 0, false);
  KeyFrame* kf2 = scene.addKeyFrame(map, v2, 1, false);
  std::size_t checked = 0;
  for (std::size_t i1 = 0; i1 < v1.scene_point.size(); ++i1) {
    for (std::size_t i2 = 0; i2 < v2.scene_point.size(); ++i2) {
      if (v1.scene_point[i1] != v2.scene_point[i2]) continue;
      const auto x = triangulateMatchedPair(*kf1, i1, *kf2, i2, scene.camera());
      ASSERT_TRUE(x.has_value());
      const Eigen::Vector3d& truth = scene.points()[static_cast<std::size_t>(v1.scene_point[i1])];
      EXPECT_LT((*x - truth).norm(), 0.02);
      ++checked;
    }
  }
  EXPECT_GT(checked, 30u);
}

TEST(PairTriangulation, KeypointIndexOutsideTheKeyFrameThrows) {
  const PinholeCamera camera = test::syntheticCamera();
  const PairOfKeyFrames pair(poseAt({0, 0, 0}), {100, 100}, 0, poseAt({0.3, 0, 0}), {90, 100}, 0);
  EXPECT_THROW(triangulateKeypointPair(*pair.kf1, 1, *pair.kf2, 0, camera), std::out_of_range);
  EXPECT_THROW(triangulateKeypointPair(*pair.kf1, 0, *pair.kf2, 5, camera), std::out_of_range);
}

}  // namespace
}  // namespace edgeslam
