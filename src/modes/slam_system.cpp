#include "modes/slam_system.h"

#include <algorithm>
#include <cmath>

#include "client/frame_rate_scaling.h"

namespace edgeslam {

SlamOptions defaultSlamOptions(const PinholeCamera& camera, Sensor sensor) {
  SlamOptions options;
  options.sensor = sensor;
  options.orb.num_features = camera.width() * camera.height() > 640 * 480 * 1.2 ? 2000 : 1000;
  options.tracker.sensor = sensor;
  // No network between tracking and mapping: N = 0, below paper Table I's first row (0, 10] ms,
  // whose values we take.
  setKeyFrameGaps(options.tracker.keyframes, 10, 40, camera.intrinsics().fps);
  options.tracker.keyframes.alpha = 0.3;
  options.tracker.keyframes.beta = 0.9;
  // Without depth a focal change trades against the map's shape, so a monocular map's own focal
  // estimate is trusted less: on 7-Scenes the monocular map asked for -5.8 % (585 -> 551-558) and
  // its keyframes got worse (ATE 4.23 -> 4.78 cm), while KITTI's -1.1 % takes its turn drift out.
  // The RGB-D map of the same 7-Scenes frames measures -7 % (545) with depth, and gains.
  if (sensor == Sensor::kMonocular) options.intrinsics_refinement.max_focal_change = 0.03;
  return options;
}

TrackingSlam::TrackingSlam(const PinholeCamera& camera, SlamOptions options,
                           std::uint8_t map_id_origin)
    : camera_(camera),
      options_(std::move(options)),
      extractor_(options_.orb),
      map_(map_id_origin),
      levels_wanted_(options_.orb.num_levels) {
  options_.tracker.sensor = options_.sensor;
  if (options_.semantic) {
    semantic_filter_ = std::make_unique<SemanticFrameFilter>(camera_, options_.semantic_filter);
    validate(options_.segmentation_refresh);
    const double fps = camera_.intrinsics().fps;
    options_.segmentation_refresh.min_frames =
        framesAtCameraRate(options_.segmentation_refresh.min_frames, fps);
    options_.segmentation_refresh.max_frames =
        framesAtCameraRate(options_.segmentation_refresh.max_frames, fps);
    options_.tracker.keyframes.segmentation_refresh =
        segmentationRefreshFrames(options_.segmentation_refresh, std::nullopt);
  }
}

void TrackingSlam::startTracking(KeyFrameSink* sink, std::function<void()> wait_until_idle) {
  if (sink != nullptr) {
    paced_sink_ = std::make_unique<PacedKeyFrameSink>(
        *sink, options_.wait_for_backend ? std::move(wait_until_idle) : std::function<void()>());
    sink = paced_sink_.get();
  }
  tracker_ = std::make_unique<Tracker>(map_, camera_, options_.tracker, sink);
}

bool TrackingSlam::setComputeStep(const ComputeStep& step) {
  compute_step_ = step;
  applyExtractionSize();
  return true;
}

void TrackingSlam::setPyramidLevels(int levels) {
  levels_wanted_ = levels;
  applyExtractionSize();
}

void TrackingSlam::applyExtractionSize() {
  const int features = compute_step_.features(options_.orb.num_features);
  const int levels = compute_step_.levels(levels_wanted_);
  if (features != extractor_.options().num_features) extractor_.setNumFeatures(features);
  if (levels != extractor_.numLevels()) extractor_.setNumLevels(levels);
}

void TrackingSlam::waitForBackend(const std::function<void()>& wait) {
  if (options_.wait_for_backend && paced_sink_) paced_sink_->waitFor(wait);
}

void TrackingSlam::noteKeyFrameDepth(KeyFrameId id) {
  std::vector<double> depths;
  {
    MutexLock lock(map_.updateMutex());
    const KeyFrame* keyframe = map_.keyFrame(id);
    if (keyframe == nullptr) return;
    const SE3d& T_cw = keyframe->pose();
    for (const MapPoint* p : keyframe->goodPoints()) {
      const double z = (T_cw * p->position()).z();
      if (z > 0.0) depths.push_back(z);
    }
  }
  if (depths.size() >= kMinPointsForDepth) keyframe_depths_.push_back(percentile(depths, 0.5));
}

double TrackingSlam::keyFrameDepthRatio() const {
  const std::size_t quarter = keyframe_depths_.size() / 4;
  if (quarter < kMinKeyFramesPerQuarter) return 0.0;
  const std::vector<double> early(keyframe_depths_.begin(), keyframe_depths_.begin() + quarter);
  const std::vector<double> late(keyframe_depths_.end() - quarter, keyframe_depths_.end());
  const double early_depth = percentile(early, 0.5);
  return early_depth > 0.0 ? percentile(late, 0.5) / early_depth : 0.0;
}

TrackResult TrackingSlam::process(std::size_t frame_index, double timestamp, const cv::Mat& gray,
                                  const cv::Mat& depth, const cv::Mat& color) {
  const cv::Mat& used_depth = options_.sensor == Sensor::kMonocular ? cv::Mat() : depth;
  Stopwatch stage;
  std::shared_ptr<const FrameFeatures> features =
      buildFrameFeatures(gray, used_depth, camera_, extractor_, options_.depth);
  const cv::Mat& image = color.empty() ? gray : color;
  if (semantic_filter_) {
    beforeCulling(frame_index, image);
    last_semantic_ = semantic_filter_->filter(frame_index, std::move(features));
    semantic_ms_.add(last_semantic_.elapsed_ms);
    features = last_semantic_.kept;
  } else {
    last_semantic_ = SemanticFrame{features, features, {}, std::nullopt, 0, 0.0};
  }
  last_stages_.features_ms = stage.elapsedMs();
  features_ms_.add(last_stages_.features_ms);
  if (semantic_filter_) {
    tracker_->keyframeParameters().segmentation_refresh = segmentationRefreshFrames(
        options_.segmentation_refresh, semantic_filter_->typicalMaskDelayFrames());
  }
  beforeTracking(frame_index, image);
  stage = Stopwatch();
  TrackResult result = tracker_->track(frame_index, timestamp, std::move(features));
  first_map_frame_.noteProgress(tracker_->records().size(), tracker_->mapsStarted());
  last_stages_.tracking_ms = stage.elapsedMs();
  tracking_ms_.add(last_stages_.tracking_ms);
  stage = Stopwatch();
  afterTracking(result, frame_index, image);
  afterFrame();
  if (options_.sensor == Sensor::kMonocular && result.new_keyframe &&
      result.keyframe != kInvalidId) {
    noteKeyFrameDepth(result.keyframe);
  }
  last_stages_.keyframe_ms = stage.elapsedMs();
  keyframe_ms_.add(last_stages_.keyframe_ms);
  return result;
}

void TrackingSlam::addClientCounters(SlamCounters& counters) const {
  counters.stages.features_ms = features_ms_.summary();
  counters.stages.tracking_ms = tracking_ms_.summary();
  counters.stages.keyframe_ms = keyframe_ms_.summary();
  if (paced_sink_) counters.backend = paced_sink_->pacing();
  counters.map.keyframe_depth_ratio = keyFrameDepthRatio();
  if (!semantic_filter_) return;
  const SemanticFilterCounters c = semantic_filter_->counters();
  counters.semantic.client_ms = semantic_ms_.summary();
  counters.semantic.frames_with_mask = c.frames_with_mask;
  counters.semantic.frames_without_mask = c.frames_without_mask;
  counters.semantic.features_culled = c.features_culled;
  counters.semantic.mask_age = c.mask_age;
}

Trajectory TrackingSlam::trajectoryAtFrameTime() const {
  Trajectory out;
  const auto& records = tracker_->records();
  for (std::size_t i = 0; i < records.size(); ++i) {
    const auto& r = records[i];
    if (r.tracked && first_map_frame_.inFirstAtFrameTime(i, r.map)) {
      out.push_back({r.timestamp, r.T_cw.inverse()});
    }
  }
  return out;
}

Trajectory TrackingSlam::trajectoryFinal() const {
  MutexLock lock(map_.updateMutex());
  Trajectory out;
  for (const auto& r : tracker_->records()) {
    if (!r.tracked || r.reference == nullptr || !first_map_frame_.inFirstFinally(r.map)) continue;
    out.push_back({r.timestamp, (r.T_cr * r.reference->latestPose()).inverse()});
  }
  return out;
}

std::vector<OwnMapTrajectory> TrackingSlam::trajectoriesInOwnFrames() const {
  std::vector<OwnMapTrajectory> out;
  const auto& records = tracker_->records();
  for (std::size_t i = 0; i < records.size(); ++i) {
    const auto& r = records[i];
    if (!r.tracked || first_map_frame_.inFirstAtFrameTime(i, r.map)) continue;
    if (out.empty() || out.back().map != r.map) out.push_back({.map = r.map, .poses = {}});
    out.back().poses.push_back({r.timestamp, r.T_cw.inverse()});
    if (!first_map_frame_.inFirstFinally(r.map)) ++out.back().never_joined;
  }
  return out;
}

Trajectory TrackingSlam::keyframeTrajectory() const {
  MutexLock lock(map_.updateMutex());
  Trajectory out;
  for (KeyFrame* kf : map_.keyFrames()) out.push_back({kf->timestamp(), kf->poseInverse()});
  return out;
}

MapSample TrackingSlam::mapSample(std::size_t max_points) const {
  MutexLock lock(map_.updateMutex());
  MapSample sample;
  const std::vector<KeyFrame*> keyframes = map_.keyFrames();
  sample.keyframe_poses.reserve(keyframes.size());
  for (const KeyFrame* kf : keyframes) {
    if (kf->isBad()) continue;
    sample.keyframe_poses.push_back(kf->poseInverse());
    sample.keyframe_ids.push_back(kf->id());
  }
  sample.points = map_.pointPositionSample(max_points);
  sample.total_points = map_.pointCount();
  return sample;
}

std::size_t TrackingSlam::keyFrameCount() const {
  MutexLock lock(map_.updateMutex());
  return map_.keyFrameCount();
}

std::size_t TrackingSlam::mapPointCount() const {
  MutexLock lock(map_.updateMutex());
  return map_.pointCount();
}

}  // namespace edgeslam
