// Map matchers on synthetic scenes (known correspondences) and their edge cases.
#include "map/map_matching.h"

#include <gtest/gtest.h>

#include <stdexcept>

#include "map/synthetic_views.h"

namespace edgeslam {
namespace {

using test::poseAt;
using test::SyntheticScene;

Frame frameFor(const test::SyntheticView& view, const PinholeCamera& camera, std::size_t index,
               bool with_pose) {
  Frame frame(index, 0.0, view.features, &camera);
  if (with_pose) frame.T_cw = view.T_cw;
  return frame;
}

// --- isInFrustum ---------------------------------------------------------------------------------

class FrustumTest : public ::testing::Test {
 protected:
  void SetUp() override {
    MutexLock lock(map_.updateMutex());
    // One keypoint at the image centre seeing a point 2 m ahead.
    const PinholeCamera& cam = scene_.camera();
    auto features = std::make_shared<FrameFeatures>();
    features->keypoints.emplace_back(320.f, 240.f, 31.f, 0.f, 20.f, 0);
    features->descriptors = cv::Mat(1, 32, CV_8UC1, cv::Scalar(7));
    features->grid = FeatureGrid(cam.undistortedBounds(), features->keypoints);
    kf_ = map_.createKeyFrame(0, 0.0, features, SE3d());
    point_ = map_.createMapPoint(Eigen::Vector3d(0, 0, 2), kf_);
    map_.addObservation(point_, kf_, 0);
    map_.refreshPoint(point_);
    frame_ = Frame(1, 0.0, features, &cam);
  }

  bool seenFrom(const SE3d& T_cw, float min_view_cos = 0.5f) {
    frame_.T_cw = T_cw;
    return isInFrustum(point_, frame_, min_view_cos);
  }

  SyntheticScene scene_{0, 1};
  Map map_;
  KeyFrame* kf_ = nullptr;
  MapPoint* point_ = nullptr;
  Frame frame_;
};

TEST_F(FrustumTest, AcceptsAVisiblePointAndFillsTheTrackingFields) {
  ASSERT_TRUE(seenFrom(poseAt({0.1, 0, 0})));
  EXPECT_TRUE(point_->track_in_view);
  EXPECT_NEAR(point_->track_projected_x, 320.f - 500.f * 0.1f / 2.f, 1e-3f);
  EXPECT_NEAR(point_->track_projected_y, 240.f, 1e-3f);
  EXPECT_GT(point_->track_view_cos, 0.99f);
  EXPECT_GE(point_->track_level, 0);
  EXPECT_LE(point_->track_level, 1);
}

TEST_F(FrustumTest, RejectsAPointBehindTheCamera) {
  EXPECT_FALSE(seenFrom(poseAt({0, 0, 3})));
  EXPECT_FALSE(point_->track_in_view);
  // Turned around at the origin: the point is behind too.
  EXPECT_FALSE(seenFrom(poseAt({0, 0, 0}, M_PI)));
}

TEST_F(FrustumTest, RejectsAPointOutsideItsDistanceRange) {
  EXPECT_TRUE(seenFrom(poseAt({0, 0, -0.3})));   // 2.3 m < 1.2 * 2 m
  EXPECT_FALSE(seenFrom(poseAt({0, 0, -1.0})));  // 3 m: too far for a level-0 observation at 2 m
  EXPECT_FALSE(point_->track_in_view);
  // min distance = 0.8 * 2 m / 1.2^7 ~ 0.45 m
  EXPECT_TRUE(seenFrom(poseAt({0, 0, 1.4})));
  EXPECT_FALSE(seenFrom(poseAt({0, 0, 1.7})));
}

TEST_F(FrustumTest, RejectsAnObliqueViewAndAPointOutsideTheImage) {
  // From the side at 60+ degrees to the normal, turned to look at the point.
  const double angle = 1.2;
  const Eigen::Vector3d center(2.0 * std::sin(angle), 0, 2.0 - 2.0 * std::cos(angle));
  EXPECT_FALSE(seenFrom(poseAt(center, -angle)));
  EXPECT_TRUE(seenFrom(poseAt(center, -angle), 0.3f));
  // Looking away sideways: in front of the camera but off the image.
  EXPECT_FALSE(seenFrom(poseAt({0, 0, 0}, 0.9)));
}

TEST_F(FrustumTest, BadPointIsNeverInViewAndMissingPoseIsAnError) {
  MutexLock lock(map_.updateMutex());
  frame_.T_cw.reset();
  EXPECT_THROW(isInFrustum(point_, frame_), std::invalid_argument);
  EXPECT_THROW(isInFrustum(nullptr, frame_), std::invalid_argument);
  map_.erasePoint(point_);
  frame_.T_cw = SE3d();
  EXPECT_FALSE(isInFrustum(point_, frame_));
}

// --- matchers on a two-view synthetic scene
// -------------------------------------------------------

class SyntheticMatching : public ::testing::Test {
 protected:
  SyntheticMatching()
      : scene_(600, 42),
        view1_(scene_.view(poseAt({0, 0, 0}), 8, false)),
        view2_(scene_.view(poseAt({0.15, 0.02, 0.05}, 0.03), 8, false)) {}

  // Fraction of the frame's matches that stand for the keypoint's own scene point.
  double correctShare(const Frame& frame, const test::SyntheticView& view) const {
    int good = 0, all = 0;
    for (std::size_t j = 0; j < frame.size(); ++j) {
      if (frame.points[j] == nullptr) continue;
      ++all;
      good += scene_.sceneOf(frame.points[j]) == view.scene_point[j];
    }
    return all == 0 ? 0.0 : static_cast<double>(good) / all;
  }

  SyntheticScene scene_;
  test::SyntheticView view1_, view2_;
  Map map_;
};

TEST_F(SyntheticMatching, ByProjectionFindsTheTrueMatches) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf = scene_.addKeyFrame(map_, view1_, 0, true);
  Frame last = frameFor(view1_, scene_.camera(), 0, true);
  last.points = kf->points();
  Frame current = frameFor(view2_, scene_.camera(), 1, true);
  const int matches = matchByProjection(current, last, 7.f, true);
  EXPECT_GT(matches, 0.8 * static_cast<double>(view2_.scene_point.size()));
  EXPECT_EQ(matches, current.matchedCount());
  EXPECT_EQ(correctShare(current, view2_), 1.0);

  // A second pass finds nothing new: every keypoint is taken or has no partner.
  EXPECT_EQ(matchByProjection(current, last, 7.f, true), 0);
}

TEST_F(SyntheticMatching, ByProjectionWithDepthUsesTheRightCoordinate) {
  SyntheticScene scene(400, 5);
  const auto v1 = scene.view(poseAt({0, 0, 0}), 8, true);
  const auto v2 = scene.view(poseAt({0.05, 0, 0.3}), 8, true);  // moving forward 30 cm
  Map map;
  MutexLock lock(map.updateMutex());
  KeyFrame* kf = scene.addKeyFrame(map, v1, 0, true);
  Frame last = frameFor(v1, scene.camera(), 0, true);
  last.points = kf->points();
  Frame current = frameFor(v2, scene.camera(), 1, true);
  const int matches = matchByProjection(current, last, 7.f, false);
  EXPECT_GT(matches, 0.8 * static_cast<double>(v2.scene_point.size()));
  for (std::size_t j = 0; j < current.size(); ++j) {
    if (current.points[j] != nullptr) {
      EXPECT_EQ(scene.sceneOf(current.points[j]), v2.scene_point[j]);
    }
  }
}

TEST_F(SyntheticMatching, LocalPointsNeedTheFrustumTestAndSkipMatchedPoints) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf = scene_.addKeyFrame(map_, view1_, 0, true);
  const std::vector<MapPoint*> points = kf->goodPoints();
  Frame frame = frameFor(view2_, scene_.camera(), 1, true);
  for (MapPoint* p : points) p->track_in_view = false;
  EXPECT_EQ(matchLocalPoints(frame, points, 1.f), 0);

  int in_view = 0;
  for (MapPoint* p : points) in_view += isInFrustum(p, frame);
  EXPECT_GT(in_view, 0.8 * static_cast<double>(points.size()));
  const int matches = matchLocalPoints(frame, points, 1.f);
  EXPECT_GT(matches, 0.9 * in_view);
  EXPECT_EQ(correctShare(frame, view2_), 1.0);
  EXPECT_EQ(matchLocalPoints(frame, points, 1.f), 0);  // all already matched
}

TEST_F(SyntheticMatching, KeyFrameByDescriptorNeedsNoPose) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf = scene_.addKeyFrame(map_, view1_, 0, true);
  Frame frame = frameFor(view2_, scene_.camera(), 1, false);
  const int matches = matchKeyFrameByDescriptor(*kf, frame);
  EXPECT_GT(matches, 0.8 * static_cast<double>(view2_.scene_point.size()));
  EXPECT_EQ(matches, frame.matchedCount());
  EXPECT_EQ(correctShare(frame, view2_), 1.0);
}

TEST_F(SyntheticMatching, KeyFrameByProjectionSkipsAlreadyMatchedPoints) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf = scene_.addKeyFrame(map_, view1_, 0, true);
  const std::vector<MapPoint*> good = kf->goodPoints();
  const std::vector<MapPoint*> first_half(good.begin(), good.begin() + good.size() / 2);
  Frame frame = frameFor(view2_, scene_.camera(), 1, true);
  const int matches = matchKeyFrameByProjection(frame, *kf, first_half, 10.f, 100);
  EXPECT_GT(matches, 0.3 * static_cast<double>(good.size()));
  EXPECT_EQ(correctShare(frame, view2_), 1.0);
  for (MapPoint* p : first_half) {
    EXPECT_EQ(std::count(frame.points.begin(), frame.points.end(), p), 0);
  }
}

TEST_F(SyntheticMatching, TriangulationPairsAreTheTrueCorrespondences) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, false);
  const auto pairs = matchForTriangulation(*kf1, *kf2, scene_.camera(), true);
  EXPECT_GT(pairs.size(), 0.7 * static_cast<double>(view2_.scene_point.size()));
  for (const auto& [i, j] : pairs) {
    EXPECT_EQ(view1_.scene_point[i], view2_.scene_point[j]);
  }
}

TEST_F(SyntheticMatching, TriangulationSkipsKeypointsThatHaveAPoint) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, true);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, false);
  EXPECT_TRUE(matchForTriangulation(*kf1, *kf2, scene_.camera(), true).empty());
  EXPECT_TRUE(matchForTriangulation(*kf2, *kf1, scene_.camera(), true).empty());
}

TEST_F(SyntheticMatching, TriangulationWithoutBaselineGivesNothing) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  const auto same_place = scene_.view(poseAt({0, 0, 0}, 0.05), 8, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, same_place, 1, false);
  EXPECT_TRUE(matchForTriangulation(*kf1, *kf2, scene_.camera(), true).empty());
}

TEST_F(SyntheticMatching, TriangulationRejectsDescriptorsTooFarApart) {
  MutexLock lock(map_.updateMutex());
  const auto noisy = scene_.view(view2_.T_cw, 100, false);  // ~80 bits differ: above 50
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, false);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, noisy, 1, false);
  EXPECT_LT(matchForTriangulation(*kf1, *kf2, scene_.camera(), true).size(),
            0.1 * static_cast<double>(noisy.scene_point.size()));
}

TEST_F(SyntheticMatching, FuseMergesDuplicatesAndAddsObservations) {
  MutexLock lock(map_.updateMutex());
  KeyFrame* kf1 = scene_.addKeyFrame(map_, view1_, 0, true);
  KeyFrame* kf2 = scene_.addKeyFrame(map_, view2_, 1, true);
  // Leave half of kf2's keypoints without a point: those gain an observation instead.
  for (std::size_t j = 0; j < kf2->size(); j += 2) map_.erasePoint(kf2->point(j));
  const std::size_t before = map_.pointCount();
  const std::size_t kf2_points = kf2->goodPoints().size();

  const int fused = fuse(map_, kf2, kf1->goodPoints(), scene_.camera());
  EXPECT_GT(fused, 0.8 * static_cast<double>(view2_.scene_point.size()));
  const std::size_t merged = before - map_.pointCount();
  EXPECT_GT(merged, 0.8 * static_cast<double>(kf2_points));
  EXPECT_LE(merged, kf2_points);

  int shared = 0;
  for (std::size_t j = 0; j < kf2->size(); ++j) {
    MapPoint* p = kf2->point(j);
    if (p == nullptr) continue;
    ASSERT_FALSE(p->isBad());
    EXPECT_EQ(p->observations().at(kf2->id()).index, j);
    if (p->observations().contains(kf1->id())) {
      ++shared;
      EXPECT_EQ(view1_.scene_point[p->observations().at(kf1->id()).index], view2_.scene_point[j]);
    }
  }
  EXPECT_EQ(shared, fused);
  // Fusing again changes nothing: every point is already observed.
  EXPECT_EQ(fuse(map_, kf2, kf1->goodPoints(), scene_.camera()), 0);
}

// --- edge cases
// -------------------------------------------------------------------------------------

TEST(MapMatchingEdgeCases, EmptyFramesAndNoPoints) {
  const PinholeCamera camera = test::syntheticCamera();
  SyntheticScene scene(200, 3);
  const auto view = scene.view(SE3d(), 4, false);
  Map map;
  MutexLock lock(map.updateMutex());
  KeyFrame* with_points = scene.addKeyFrame(map, view, 0, true);
  KeyFrame* without_points = scene.addKeyFrame(map, view, 1, false);
  KeyFrame* empty_kf = map.createKeyFrame(2, 0.0, test::emptyFeatures(camera), SE3d());

  Frame empty(5, 0.0, test::emptyFeatures(camera), &camera);
  empty.T_cw = SE3d();
  Frame full(6, 0.0, view.features, &camera);
  full.T_cw = SE3d();
  Frame last(4, 0.0, view.features, &camera);
  last.T_cw = SE3d();
  last.points = with_points->points();

  EXPECT_EQ(matchByProjection(empty, last, 7.f, true), 0);
  EXPECT_EQ(matchByProjection(full, empty, 7.f, true), 0);
  Frame no_points_last(4, 0.0, view.features, &camera);
  no_points_last.T_cw = SE3d();
  EXPECT_EQ(matchByProjection(full, no_points_last, 7.f, true), 0);

  EXPECT_EQ(matchLocalPoints(empty, with_points->goodPoints(), 1.f), 0);
  EXPECT_EQ(matchLocalPoints(full, {}, 1.f), 0);
  EXPECT_EQ(matchLocalPoints(full, {nullptr}, 1.f), 0);

  EXPECT_EQ(matchKeyFrameByDescriptor(*with_points, empty), 0);
  EXPECT_EQ(matchKeyFrameByDescriptor(*without_points, full), 0);
  EXPECT_EQ(matchKeyFrameByDescriptor(*empty_kf, full), 0);

  EXPECT_EQ(matchKeyFrameByProjection(empty, *with_points, {}, 10.f, 100), 0);
  EXPECT_EQ(matchKeyFrameByProjection(full, *without_points, {}, 10.f, 100), 0);
  EXPECT_EQ(full.matchedCount(), 0);

  EXPECT_TRUE(matchForTriangulation(*empty_kf, *without_points, camera, true).empty());
  EXPECT_TRUE(matchForTriangulation(*without_points, *empty_kf, camera, false).empty());

  EXPECT_EQ(fuse(map, empty_kf, with_points->goodPoints(), camera), 0);
  EXPECT_EQ(fuse(map, without_points, {}, camera), 0);
  EXPECT_EQ(fuse(map, without_points, {nullptr}, camera), 0);
}

TEST(MapMatchingEdgeCases, MissingPoseOrCameraIsAClearError) {
  const PinholeCamera camera = test::syntheticCamera();
  SyntheticScene scene(50, 4);
  const auto view = scene.view(SE3d(), 4, false);
  Map map;
  MutexLock lock(map.updateMutex());
  KeyFrame* kf = scene.addKeyFrame(map, view, 0, true);
  Frame posed(1, 0.0, view.features, &camera);
  posed.T_cw = SE3d();
  Frame unposed(2, 0.0, view.features, &camera);
  EXPECT_THROW(matchByProjection(unposed, posed, 7.f, true), std::invalid_argument);
  EXPECT_THROW(matchByProjection(posed, unposed, 7.f, true), std::invalid_argument);
  EXPECT_THROW(matchKeyFrameByProjection(unposed, *kf, {}, 10.f, 100), std::invalid_argument);
  Frame no_camera(3, 0.0, view.features, nullptr);
  no_camera.T_cw = SE3d();
  EXPECT_THROW(matchByProjection(no_camera, posed, 7.f, true), std::invalid_argument);
  Frame broken = posed;
  broken.points.pop_back();
  EXPECT_THROW(matchKeyFrameByDescriptor(*kf, broken), std::invalid_argument);
  EXPECT_THROW(fuse(map, nullptr, kf->goodPoints(), camera), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
