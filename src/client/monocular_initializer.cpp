#include "client/monocular_initializer.h"

#include <fmt/format.h>

#include "features/descriptor_matching.h"
#include "optimize/map_optimization.h"

namespace edgeslam {

MonocularInitializer::MonocularInitializer(const PinholeCamera& camera,
                                           MonocularInitializerOptions options)
    : camera_(camera), options_(std::move(options)) {}

void MonocularInitializer::resetReference(const Frame& frame) {
  reference_.reset();
  if (frame.size() >= static_cast<std::size_t>(options_.min_features)) reference_ = frame;
}

void MonocularInitializer::refuse(InitRefusal refusal, std::string why) {
  last_refusal_ = refusal;
  last_failure_ = std::move(why);
}

KeyFrame* MonocularInitializer::tryInitialize(Frame& frame, Map& map) {
  last_refusal_.reset();
  // A featureless frame (blank, overexposed) neither serves as a reference nor initialises.
  if (frame.size() < static_cast<std::size_t>(options_.min_features)) {
    refuse(InitRefusal::kTooFewFeatures,
           fmt::format("{} features, need {}", frame.size(), options_.min_features));
    return nullptr;
  }
  if (!reference_ || frame.index - reference_->index > options_.max_reference_age) {
    resetReference(frame);
    last_failure_ = "waiting for a second frame";
    return nullptr;
  }
  const FrameFeatures& ref = *reference_->features;
  const FrameFeatures& cur = *frame.features;
  MatchOptions match_options;
  match_options.ratio = 0.9;
  match_options.max_distance = kMatchDistanceLow;
  const std::vector<cv::DMatch> matches =
      matchInWindow(ref.keypoints, ref.descriptors, cur.keypoints, cur.descriptors, cur.grid,
                    options_.search_radius, match_options, 0);
  if (matches.size() < static_cast<std::size_t>(options_.min_matches)) {
    refuse(InitRefusal::kTooFewMatches, fmt::format("{} matches to the reference frame, need {}",
                                                    matches.size(), options_.min_matches));
    resetReference(frame);
    return nullptr;
  }

  std::vector<Eigen::Vector2d> ref_px, cur_px;
  ref_px.reserve(matches.size());
  cur_px.reserve(matches.size());
  for (const cv::DMatch& m : matches) {
    const cv::Point2f& a = ref.keypoints[static_cast<std::size_t>(m.queryIdx)].pt;
    const cv::Point2f& b = cur.keypoints[static_cast<std::size_t>(m.trainIdx)].pt;
    ref_px.emplace_back(a.x, a.y);
    cur_px.emplace_back(b.x, b.y);
  }
  ++attempts_;
  TwoViewResult two_view = initializeTwoView(ref_px, cur_px, camera_.K(), options_.two_view);
  if (!two_view.success) {
    refuse(refusalFor(two_view.failure), two_view.reason);
    return nullptr;
  }

  KeyFrame* kf0 = nullptr;
  KeyFrame* kf1 = nullptr;
  bool alone = true;  // the map holds nothing else
  {
    MutexLock lock(map.updateMutex());
    alone = map.keyFrameCount() == 0;
    kf0 =
        map.createKeyFrame(reference_->index, reference_->timestamp, reference_->features, SE3d());
    kf1 = map.createKeyFrame(frame.index, frame.timestamp, frame.features,
                             two_view.current_from_reference);
    for (std::size_t i = 0; i < matches.size(); ++i) {
      if (!two_view.triangulated[i]) continue;
      MapPoint* p = map.createMapPoint(two_view.points_reference[i], kf0);
      map.addObservation(p, kf0, static_cast<std::size_t>(matches[i].queryIdx));
      map.addObservation(p, kf1, static_cast<std::size_t>(matches[i].trainIdx));
      map.refreshPoint(p);
    }
    map.updateConnections(kf0);
    map.updateConnections(kf1);
  }

  if (alone) {
    globalBundleAdjustment(map, camera_, nullptr, 20);
  } else {
    // Only the two new keyframes and their points, the first held (BA holds the oldest keyframe
    // of a part without the map's origin).
    BundleAdjustmentOptions two_view_ba = BundleAdjustmentOptions::global();
    two_view_ba.first_pass_iterations = 20;
    localBundleAdjustment(map, kf1, camera_, nullptr, two_view_ba);
  }

  MutexLock lock(map.updateMutex());
  const double median_depth = kf0->medianSceneDepth();
  const int tracked = kf1->trackedPointCount(1);
  if (median_depth <= 0.0 || tracked < options_.min_map_points) {
    refuse(InitRefusal::kWeakMap,
           fmt::format("initial map too weak ({} points, median depth {:.3f})", tracked,
                       median_depth));
    if (alone) {
      map.clear();
    } else {  // the older map stays
      for (MapPoint* p : kf0->goodPoints()) map.erasePoint(p);
      map.eraseKeyFrame(kf1);
      map.eraseKeyFrame(kf0);
    }
    resetReference(frame);
    return nullptr;
  }
  // Fix the monocular scale: median depth of the first keyframe = 1.
  const double inv = 1.0 / median_depth;
  SE3d T1 = kf1->pose();
  T1.setTranslation(T1.translation() * inv);
  map.setKeyFramePose(kf1, T1);
  for (MapPoint* p : kf0->goodPoints()) {
    map.setPointPosition(p, p->position() * inv);
    map.refreshPoint(p);
  }
  frame.T_cw = kf1->pose();
  for (std::size_t i = 0; i < frame.size(); ++i) {
    frame.points[i] = kf1->point(i);
    frame.outliers[i] = false;
  }
  frame.reference_keyframe = kf1;
  reference_.reset();
  reference_keyframe_ = kf0;
  return kf1;
}

}  // namespace edgeslam
