// Map matchers on real 7-Scenes frames (redkitchen): keyframe 0 with points from its depth image,
// matched into later frames at their ground-truth poses. Skipped when the data is absent.
#include <gtest/gtest.h>

#include <chrono>
#include <cstdio>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>
#include <string>

#include "features/descriptor_matching.h"
#include "features/frame_features_builder.h"
#include "features/orb_extractor.h"
#include "geometry/pnp.h"
#include "geometry/triangulation.h"
#include "map/map_matching.h"
#include "map/seven_scenes_frames.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

using test::sevenScenesCamera;
using RealFrame = test::SevenScenesFrame;
const RealFrame& realFrame(int index) {
  return test::sevenScenesFrame(index);
}

Eigen::Vector3d pointFromDepth(const FrameFeatures& f, std::size_t i, const PinholeCamera& camera,
                               const SE3d& T_cw) {
  const Eigen::Vector3d ray = camera.unproject({f.keypoints[i].pt.x, f.keypoints[i].pt.y});
  return T_cw.inverse() * (ray * f.depth[i]);
}

// Colour and depth are not perfectly registered: a corner on an object's outline often gets the
// depth of what lies behind. Keypoints on locally smooth depth make trustworthy 3-D points.
bool depthIsSmooth(const cv::Mat& depth, const cv::KeyPoint& kp) {
  constexpr int kHalf = 3;
  const int x = cvRound(kp.pt.x), y = cvRound(kp.pt.y);
  if (x < kHalf || y < kHalf || x >= depth.cols - kHalf || y >= depth.rows - kHalf) return false;
  float lo = 1e9f, hi = 0.f;
  for (int dy = -kHalf; dy <= kHalf; ++dy) {
    for (int dx = -kHalf; dx <= kHalf; ++dx) {
      const float d = depth.at<float>(y + dy, x + dx);
      if (d <= 0.f) return false;
      lo = std::min(lo, d);
      hi = std::max(hi, d);
    }
  }
  return hi - lo < 0.02f * lo;
}

// KinectFusion's poses are the depth camera's and, seen through the colour image, off by up to a
// centimetre and a degree (several pixels). Matches are judged against the pose that best explains
// `index` seen from `reference`: PnP (RANSAC + refinement) on brute-force descriptor matches (a
// matcher independent of the ones under test) to the reference's smooth depth points; the result
// must stay close to the ground truth.
SE3d refinedPose(int reference, int index, const PinholeCamera& camera) {
  static std::map<std::pair<int, int>, SE3d> cache;
  if (const auto it = cache.find({reference, index}); it != cache.end()) return it->second;
  const RealFrame& ref = realFrame(reference);
  const RealFrame& rf = realFrame(index);
  MatchOptions options;
  options.ratio = 0.7;
  const auto matches = matchBruteForce(ref.features->keypoints, ref.features->descriptors,
                                       rf.features->keypoints, rf.features->descriptors, options);
  std::vector<Eigen::Vector2d> pixels;
  std::vector<Eigen::Vector3d> points;
  for (const cv::DMatch& m : matches) {
    const auto i = static_cast<std::size_t>(m.queryIdx);
    if (!ref.features->hasDepth(i) || !depthIsSmooth(ref.depth, ref.features->keypoints[i])) {
      continue;
    }
    points.push_back(pointFromDepth(*ref.features, i, camera, ref.T_cw));
    const cv::Point2f& pt = rf.features->keypoints[static_cast<std::size_t>(m.trainIdx)].pt;
    pixels.emplace_back(pt.x, pt.y);
  }
  const PnpResult pnp = solvePnpRansac(pixels, points, camera.K());
  if (!pnp.success || pnp.num_inliers < 30) {
    throw std::runtime_error("PnP of frame " + std::to_string(index) + " against " +
                             std::to_string(reference) + " failed: " + pnp.reason);
  }
  const SE3d& T_cw = pnp.camera_from_world;
  const double moved = (T_cw.inverse().translation() - rf.T_cw.inverse().translation()).norm();
  const double turned = rotationDistance(T_cw, rf.T_cw);
  if (moved > 0.05 || turned > 0.05) {
    throw std::runtime_error("PnP pose of frame " + std::to_string(index) +
                             " is far from the ground truth");
  }
  std::printf("refined pose of frame %d: %d/%zu inliers, %.1f mm and %.2f deg from ground truth\n",
              index, pnp.num_inliers, pixels.size(), 1000.0 * moved, turned * 180.0 / M_PI);
  return cache.emplace(std::make_pair(reference, index), T_cw).first->second;
}

// Pose of a frame of the map built on frame 0: frame 0 keeps its ground truth, later ones are
// refined against it.
SE3d poseOf(int index, const PinholeCamera& camera) {
  return index == 0 ? realFrame(0).T_cw : refinedPose(0, index, camera);
}

// A keyframe at `T_cw` with one map point per keypoint that has depth.
KeyFrame* keyFrameWithDepthPoints(Map& map, int index, const SE3d& T_cw,
                                  const PinholeCamera& camera) REQUIRES(map.updateMutex()) {
  const RealFrame& rf = realFrame(index);
  KeyFrame* kf =
      map.createKeyFrame(static_cast<std::size_t>(index), index / 30.0, rf.features, T_cw);
  for (std::size_t i = 0; i < rf.features->size(); ++i) {
    if (!rf.features->hasDepth(i)) continue;
    MapPoint* p = map.createMapPoint(pointFromDepth(*rf.features, i, camera, T_cw), kf);
    map.addObservation(p, kf, i);
    map.refreshPoint(p);
  }
  return kf;
}

// How many of a frame's matches land near the projection of their point at the reference pose.
// The depth-derived points themselves are only good to a few pixels, hence two tolerances.
struct ProjectionCheck {
  int matches = 0;
  int within_4px = 0;
  int within_8px = 0;
  double share4() const { return matches == 0 ? 0.0 : static_cast<double>(within_4px) / matches; }
  double share8() const { return matches == 0 ? 0.0 : static_cast<double>(within_8px) / matches; }
};

ProjectionCheck checkAgainstProjection(const Frame& frame, const SE3d& T_cw,
                                       const PinholeCamera& camera) {
  ProjectionCheck check;
  for (std::size_t j = 0; j < frame.size(); ++j) {
    const MapPoint* p = frame.points[j];
    if (p == nullptr) continue;
    ++check.matches;
    const cv::Point2f& pt = frame.features->keypoints[j].pt;
    const double e2 = reprojectionErrorSquared(camera, T_cw, p->position(), {pt.x, pt.y});
    check.within_4px += e2 < 16.0;
    check.within_8px += e2 < 64.0;
  }
  return check;
}

void print(const char* what, int matches, const ProjectionCheck& check) {
  std::printf("%s: %d matches, %.1f %% within 4 px, %.1f %% within 8 px\n", what, matches,
              100.0 * check.share4(), 100.0 * check.share8());
}

// Wall time of `runs` calls (after `setup` each), printed for the report: the minimum is the
// figure to quote on a busy machine, the median shows the spread.
void time(const char* what, int runs, const std::function<void()>& setup,
          const std::function<void()>& call) {
  std::vector<double> ms;
  for (int r = 0; r < runs; ++r) {
    setup();
    const auto start = std::chrono::steady_clock::now();
    call();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
                     .count());
  }
  std::sort(ms.begin(), ms.end());
  std::printf("[timing] %s: min %.3f ms, median %.3f ms over %d runs\n", what, ms.front(),
              ms[ms.size() / 2], runs);
}

class MapMatchingRealData : public ::testing::Test {
 protected:
  void SetUp() override {
    EDGESLAM_REQUIRE_SHARED(test::kSevenScenesSequence);
    MutexLock lock(map_.updateMutex());
    kf0_ = keyFrameWithDepthPoints(map_, 0, poseOf(0, camera_), camera_);
  }

  Frame frame(int index, bool with_pose) const {
    const RealFrame& rf = realFrame(index);
    Frame f(static_cast<std::size_t>(index), index / 30.0, rf.features, &camera_);
    if (with_pose) f.T_cw = poseOf(index, camera_);
    return f;
  }

  PinholeCamera camera_ = sevenScenesCamera();
  Map map_;
  KeyFrame* kf0_ = nullptr;
};

TEST_F(MapMatchingRealData, KeyFrameHasManyDepthPoints) {
  EXPECT_GT(kf0_->goodPoints().size(), 700u);
}

TEST_F(MapMatchingRealData, ByProjectionFromTheLastFrame) {
  Frame last = frame(0, true);
  last.points = kf0_->points();
  for (const bool monocular : {true, false}) {
    Frame current = frame(10, true);
    const int matches = matchByProjection(current, last, 7.f, monocular);
    const ProjectionCheck check = checkAgainstProjection(current, *current.T_cw, camera_);
    print(monocular ? "matchByProjection r=7 (mono)" : "matchByProjection r=7 (rgbd)", matches,
          check);
    EXPECT_EQ(matches, check.matches);
    EXPECT_GT(matches, 400);
    // A 7-scale-pixel window with Hamming <= 100 and no ratio test also picks up look-alikes for
    // points whose keypoint was not detected again; pose optimisation rejects those.
    EXPECT_GT(check.share4(), 0.65);
    EXPECT_GT(check.share8(), 0.85);
  }
  Frame current = frame(10, true);
  time(
      "matchByProjection r=7 rgbd", 51, [&] { current = frame(10, true); },
      [&] { matchByProjection(current, last, 7.f, false); });
}

TEST_F(MapMatchingRealData, LocalPointsAfterTheFrustumTest) {
  Frame current = frame(10, true);
  const std::vector<MapPoint*> points = kf0_->goodPoints();
  int in_view = 0;
  for (MapPoint* p : points) in_view += isInFrustum(p, current);
  EXPECT_GT(in_view, 0.8 * static_cast<double>(points.size()));
  const int matches = matchLocalPoints(current, points, 1.f);
  const ProjectionCheck check = checkAgainstProjection(current, *current.T_cw, camera_);
  print("matchLocalPoints", matches, check);
  EXPECT_GT(matches, 350);
  EXPECT_GT(check.share4(), 0.9);

  time(
      "isInFrustum x all points", 51, [] {},
      [&] {
        for (MapPoint* p : points) isInFrustum(p, current);
      });
  time(
      "matchLocalPoints", 51, [&] { current = frame(10, true); },
      [&] { matchLocalPoints(current, points, 1.f); });
}

TEST_F(MapMatchingRealData, KeyFrameByDescriptorWithoutPose) {
  Frame current = frame(10, false);
  const int matches = matchKeyFrameByDescriptor(*kf0_, current);
  const ProjectionCheck check = checkAgainstProjection(current, poseOf(10, camera_), camera_);
  print("matchKeyFrameByDescriptor", matches, check);
  EXPECT_GT(matches, 200);
  EXPECT_GT(check.share4(), 0.88);
  EXPECT_GT(check.share8(), 0.92);
  time(
      "matchKeyFrameByDescriptor", 21, [&] { current = frame(10, false); },
      [&] { matchKeyFrameByDescriptor(*kf0_, current); });
}

TEST_F(MapMatchingRealData, KeyFrameByProjectionAddsToAPartialMatch) {
  const std::vector<MapPoint*> good = kf0_->goodPoints();
  // Pretend relocalisation matched every third point already.
  std::vector<MapPoint*> already;
  for (std::size_t k = 0; k < good.size(); k += 3) already.push_back(good[k]);

  // The two passes of relocalisation: wide and loose, then narrow and strict.
  struct Pass {
    float radius;
    int max_distance;
    int min_matches;
    double min_share4, min_share8;
  };
  for (const Pass& pass : {Pass{10.f, 100, 300, 0.55, 0.72}, Pass{3.f, 64, 220, 0.88, 0.95}}) {
    Frame current = frame(10, true);
    const int matches =
        matchKeyFrameByProjection(current, *kf0_, already, pass.radius, pass.max_distance);
    const ProjectionCheck check = checkAgainstProjection(current, *current.T_cw, camera_);
    char label[64];
    std::snprintf(label, sizeof(label), "matchKeyFrameByProjection r=%g d=%d", pass.radius,
                  pass.max_distance);
    print(label, matches, check);
    EXPECT_GT(matches, pass.min_matches);
    EXPECT_GT(check.share4(), pass.min_share4);
    EXPECT_GT(check.share8(), pass.min_share8);
    for (MapPoint* p : already) {
      EXPECT_EQ(std::count(current.points.begin(), current.points.end(), p), 0);
    }
  }
  Frame current = frame(10, true);
  time(
      "matchKeyFrameByProjection r=10", 51, [&] { current = frame(10, true); },
      [&] { matchKeyFrameByProjection(current, *kf0_, already, 10.f, 100); });
}

TEST_F(MapMatchingRealData, TriangulationPairsAgreeWithDepth) {
  // Frames 255 and 285 are 24 cm apart sideways and turned by 3 degrees: enough parallax for DLT
  // to resolve centimetres (from frame 0 the camera moves mostly forward and slowly).
  const int first = 255, second = 285;
  const RealFrame& a = realFrame(first);
  const RealFrame& b = realFrame(second);
  const SE3d T1 = a.T_cw;
  const SE3d T2 = refinedPose(first, second, camera_);
  Map map;
  MutexLock lock(map.updateMutex());
  KeyFrame* kf1 = map.createKeyFrame(first, first / 30.0, a.features, T1);
  KeyFrame* kf2 = map.createKeyFrame(second, second / 30.0, b.features, T2);

  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  for (const bool monocular : {true, false}) {
    pairs = matchForTriangulation(*kf1, *kf2, camera_, monocular);
    // Judged on kf1 keypoints whose depth is trustworthy: the kf2 keypoint must lie where the
    // depth point projects, and the DLT point must agree with the depth point.
    int checked = 0, consistent = 0, within_5_percent = 0;
    std::vector<double> errors;
    for (const auto& [i, j] : pairs) {
      ASSERT_LT(i, kf1->size());
      ASSERT_LT(j, kf2->size());
      if (!a.features->hasDepth(i) || !depthIsSmooth(a.depth, a.features->keypoints[i])) continue;
      ++checked;
      const Eigen::Vector3d from_depth = pointFromDepth(*a.features, i, camera_, T1);
      const cv::Point2f& p1 = a.features->keypoints[i].pt;
      const cv::KeyPoint& kp2 = b.features->keypoints[j];
      const double scale = b.features->scales.scale(kp2.octave);
      consistent += reprojectionErrorSquared(camera_, T2, from_depth, {kp2.pt.x, kp2.pt.y}) <
                    9.0 * scale * scale;
      const auto x =
          triangulatePixels(camera_, T1, {p1.x, p1.y}, camera_, T2, {kp2.pt.x, kp2.pt.y});
      const double error = x ? (*x - from_depth).norm() : 1e9;
      errors.push_back(error);
      within_5_percent += error < 0.05 * depthInCamera(T1, from_depth);
    }
    std::sort(errors.begin(), errors.end());
    const double median = errors.empty() ? 1e9 : errors[errors.size() / 2];
    std::printf(
        "matchForTriangulation (%s): %zu pairs, %d judged, %.1f %% at the depth point's "
        "projection, %.1f %% of DLT points within 5 %% of depth, median error %.1f cm\n",
        monocular ? "mono" : "rgbd", pairs.size(), checked,
        checked ? 100.0 * consistent / checked : 0.0,
        checked ? 100.0 * within_5_percent / checked : 0.0, 100.0 * median);
    EXPECT_GT(pairs.size(), 80u);
    EXPECT_GT(checked, 40);
    EXPECT_GT(consistent, 0.85 * checked);
    EXPECT_GT(within_5_percent, 0.75 * checked);
    EXPECT_LT(median, 0.05);
  }

  // A looser ratio gives more pairs.
  const auto loose = matchForTriangulation(*kf1, *kf2, camera_, true, 0.8f);
  std::printf("matchForTriangulation ratio 0.8: %zu pairs\n", loose.size());
  EXPECT_GT(loose.size(), pairs.size());

  // Keypoints that already have a point take no part.
  Map with_points;
  MutexLock with_points_lock(with_points.updateMutex());
  KeyFrame* kf1_points = keyFrameWithDepthPoints(with_points, first, T1, camera_);
  KeyFrame* kf2_bare = with_points.createKeyFrame(second, second / 30.0, b.features, T2);
  const auto partial = matchForTriangulation(*kf1_points, *kf2_bare, camera_, true);
  for (const auto& [i, j] : partial) EXPECT_EQ(kf1_points->point(i), nullptr);
  EXPECT_LT(partial.size(), pairs.size());

  time(
      "matchForTriangulation (1000 x 1000 keypoints)", 21, [] {},
      [&] { pairs = matchForTriangulation(*kf1, *kf2, camera_, true); });
}

TEST_F(MapMatchingRealData, FuseMergesDuplicatedPoints) {
  MutexLock lock(map_.updateMutex());
  // Keyframe 10 gets its own points from its depth: duplicates of keyframe 0's.
  KeyFrame* kf10 = keyFrameWithDepthPoints(map_, 10, poseOf(10, camera_), camera_);
  const std::size_t before = map_.pointCount();
  const std::vector<MapPoint*> kf0_points = kf0_->goodPoints();
  const int fused = fuse(map_, kf10, kf0_points, camera_);
  const std::size_t merged = before - map_.pointCount();
  std::printf("fuse: %d fused, %zu merged, %zu -> %zu points\n", fused, merged, before,
              map_.pointCount());
  EXPECT_GT(fused, 300);
  EXPECT_GT(merged, 250u);

  // Merged points are seen by both keyframes, consistently on both sides, near their keypoints.
  int shared = 0, close = 0;
  for (std::size_t j = 0; j < kf10->size(); ++j) {
    MapPoint* p = kf10->point(j);
    if (p == nullptr || !p->observations().contains(kf0_->id())) continue;
    ++shared;
    EXPECT_EQ(kf0_->point(p->observations().at(kf0_->id()).index), p);
    EXPECT_EQ(p->observations().at(kf10->id()).index, j);
    EXPECT_GE(p->observationCount(), 3);  // RGB-D observations count 2
    const cv::Point2f& pt = kf10->features().keypoints[j].pt;
    close += reprojectionErrorSquared(camera_, kf10->pose(), p->position(), {pt.x, pt.y}) < 16.0;
  }
  // Two kf0 points fused into one keypoint end up as one shared point.
  EXPECT_LE(shared, fused);
  EXPECT_GT(shared, 0.85 * fused);
  EXPECT_GT(close, 0.9 * shared);

  // Timing on a fresh copy of the situation each run.
  std::unique_ptr<Map> timing_map;
  std::vector<MapPoint*> timing_points;
  KeyFrame* timing_kf = nullptr;
  time(
      "fuse", 11,
      [&] {
        timing_map = std::make_unique<Map>();
        MutexLock timing_lock(timing_map->updateMutex());
        KeyFrame* k0 = keyFrameWithDepthPoints(*timing_map, 0, poseOf(0, camera_), camera_);
        timing_kf = keyFrameWithDepthPoints(*timing_map, 10, poseOf(10, camera_), camera_);
        timing_points = k0->goodPoints();
      },
      [&] {
        MutexLock timing_lock(timing_map->updateMutex());
        fuse(*timing_map, timing_kf, timing_points, camera_);
      });
}

}  // namespace
}  // namespace edgeslam
