#include "client/tracker.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include "geometry/pnp.h"
#include "map/map_matching.h"
#include "map/pair_triangulation.h"
#include "optimize/map_optimization.h"

namespace edgeslam {
namespace {

// Frames from the last tracked one to `frame_index` (1 when there is none to count from).
std::size_t framesSince(const std::optional<Frame>& last, std::size_t frame_index) {
  return last && last->index < frame_index ? frame_index - last->index : 1;
}

// The constant per-frame motion that makes up `motion` over `frames` frames.
SE3d perFrameMotion(const SE3d& motion, std::size_t frames) {
  if (frames <= 1) return motion;
  return SE3d::exp(motion.log() / static_cast<double>(frames));
}

// A map started after the old one was lost begins where the camera was last tracked: the
// initialiser's two keyframes and their points (the first keyframe at the origin) move rigidly
// to that pose, and so does the frame that completed them.
void placeNewMap(Map& map, KeyFrame& first, KeyFrame& second, const SE3d& start, Frame& frame)
    REQUIRES(map.updateMutex()) {
  const SE3d start_inverse = start.inverse();  // initialiser's world -> the map's world
  for (MapPoint* p : first.goodPoints()) map.relocatePoint(p, start_inverse * p->position());
  map.setKeyFramePose(&first, first.pose() * start);
  map.setKeyFramePose(&second, second.pose() * start);
  if (frame.T_cw) frame.T_cw = *frame.T_cw * start;
}

}  // namespace

const char* toString(TrackingState state) {
  switch (state) {
    case TrackingState::kNotInitialized:
      return "not initialised";
    case TrackingState::kOk:
      return "ok";
    case TrackingState::kLost:
      return "lost";
  }
  return "?";
}

Tracker::Tracker(Map& map, const PinholeCamera& camera, TrackerOptions options, KeyFrameSink* sink)
    : map_(map),
      camera_(camera),
      options_(std::move(options)),
      sink_(sink),
      mono_init_(camera, options_.monocular_init),
      map_participant_(map, "tracking") {
  if (options_.vocabulary) places_ = std::make_unique<KeyFramePlaces>(options_.vocabulary);
}

void Tracker::remember(KeyFrame* keyframe) {
  if (!places_ || keyframe == nullptr) return;
  std::shared_ptr<const KeyFramePlace> place = places_->add(*keyframe);
  // Triangulation at keyframes searches pairs through the direct index (local mapping describes
  // its keyframes its own way).
  if (options_.triangulate_at_keyframes && keyframe->place() == nullptr) {
    keyframe->setPlace(std::move(place));
  }
}

void Tracker::localizeInMap() {
  if (!places_) {
    throw std::invalid_argument("localisation in a stored map needs a vocabulary");
  }
  MutexLock lock(map_.updateMutex());
  std::size_t filed = 0;
  for (KeyFrame* keyframe : map_.keyFrames()) {
    if (keyframe->isBad() || keyframe->isEvicted()) continue;
    remember(keyframe);
    ++filed;
  }
  if (filed == 0) throw std::invalid_argument("localisation: the map has no keyframes");
  state_ = TrackingState::kLost;
}

void Tracker::localizeInArrivingMap() {
  if (!options_.localization_only) {
    throw std::logic_error("localisation through the edge needs TrackerOptions::localization_only");
  }
  state_ = TrackingState::kLost;
}

void Tracker::onMapWindowChanged(const std::vector<KeyFrameId>& evicted,
                                 const std::vector<KeyFrameId>& entered) {
  MutexLock lock(map_.updateMutex());
  if (!places_) return;
  for (KeyFrameId id : evicted) places_->erase(id);
  for (KeyFrameId id : entered) {
    KeyFrame* kf = map_.keyFrame(id);
    if (kf != nullptr && !kf->isBad() && !kf->isEvicted()) places_->add(*kf);
  }
}

std::size_t Tracker::placesSize() const {
  MutexLock lock(map_.updateMutex());
  return places_ ? places_->size() : 0;
}

TrackResult Tracker::track(std::size_t frame_index, double timestamp,
                           std::shared_ptr<const FrameFeatures> features) {
  Frame frame(frame_index, timestamp, std::move(features), &camera_);
  TrackResult result;

  if (state_ == TrackingState::kNotInitialized) {
    ++diagnostics_.frames_without_map;
    if (initialize(frame)) {
      if (!diagnostics_.initialized_at_frame) diagnostics_.initialized_at_frame = frame_index;
      ++diagnostics_.initializations;
      current_map_initialised_at_ = frame.timestamp;
      state_ = TrackingState::kOk;
      result.new_keyframe = true;
      if (reference_keyframe_ != nullptr) result.keyframe = reference_keyframe_->id();
      last_frame_ = frame;
      record(frame, true);
      result.state = state_;
      result.T_cw = frame.T_cw;
      result.tracked_points = frame.matchedCount();
    } else {
      record(frame, false);
      result.state = state_;
    }
    return result;
  }

  KeyFrame* new_keyframe = nullptr;
  bool ok = false;
  bool recovered = false;  // by the motion prediction, after some lost frames
  {
    MutexLock lock(map_.updateMutex());
    releaseErased();
    if (last_frame_ && last_frame_->T_cw) {
      // The last frame's keyframe may have moved since (local BA, a merge): follow it, through
      // the spanning tree when the edge has culled it meanwhile. A merged client whose last
      // keyframe was culled as a revisit of the other part kept its pre-merge pose and was lost.
      const FrameRecord& last_record = records_.back();
      if (last_record.tracked && last_record.reference != nullptr) {
        last_frame_->T_cw = last_record.T_cr * last_record.reference->latestPose();
      }
    }
    if (state_ == TrackingState::kOk) {
      // Frames skipped by a live camera (a client behind it) leave gaps: the prediction spans them.
      ok = velocity_ && trackWithMotionModel(frame, framesSince(last_frame_, frame_index));
      if (!ok) ok = trackReferenceKeyFrame(frame);
    } else {
      if (canRecoverByPrediction(frame_index) &&
          trackWithMotionModel(frame, frame_index - last_frame_->index)) {
        ok = true;
        recovered = true;
      } else {
        ok = relocalize(frame);
      }
      if (ok && !recovered) {
        velocity_.reset();  // the camera may be anywhere: no motion carries over the gap
        result.relocalized = true;
        ++relocalizations_;
        last_relocalization_frame_ = frame_index;
        spdlog::info("relocalised at frame {}", frame_index);
      }
    }
    frame.reference_keyframe = reference_keyframe_;

    int inliers = 0;
    if (ok) {
      inliers = trackLocalMap(frame);
      const bool recently_relocalized =
          relocalizations_ > 0 && frame_index < last_relocalization_frame_ + 30;
      spdlog::debug("frame {}: local map inliers {}", frame_index, inliers);
      ok = inliers >= (recently_relocalized ? options_.min_inliers_local_map_after_relocalization
                                            : options_.min_inliers_local_map);
    }

    if (ok) {
      if (recovered) {
        ++recoveries_;
        spdlog::info("tracking recovered at frame {} by the motion prediction, {} frames lost",
                     frame_index, frames_lost_);
      }
      if (state_ != TrackingState::kOk) frames_lost_ = 0;
      lost_since_.reset();
      state_ = TrackingState::kOk;
      // The velocity is per frame: over a gap (frames skipped or lost) the motion since the last
      // tracked frame is spread evenly over it, so the next prediction spans its own gap. Not
      // after a relocalisation: the camera may have gone anywhere since the last tracked frame.
      if (!result.relocalized && last_frame_ && last_frame_->T_cw &&
          last_frame_->index < frame_index) {
        velocity_ = perFrameMotion(*frame.T_cw * last_frame_->T_cw->inverse(),
                                   frame_index - last_frame_->index);
      }
      const KeyFrameDecision decision =
          options_.localization_only ? KeyFrameDecision::kNo : decide(frame, inliers);
      if (isKeyFrame(decision)) {
        keyframe_decisions_.add(decision);
        new_keyframe = createKeyFrame(frame);
      }
      result.tracked_points = inliers;
    } else {
      if (state_ == TrackingState::kOk) spdlog::warn("tracking lost at frame {}", frame_index);
      diagnostics_.lose(frame.size() < options_.min_trackable_features
                            ? LostCause::kTooFewFeatures
                            : LostCause::kTrackingFailed);
      state_ = TrackingState::kLost;
      ++frames_lost_;
      if (!lost_since_) lost_since_ = frame.timestamp;
      if (!canRecoverByPrediction(frame_index + 1)) velocity_.reset();
    }
    for (std::size_t i = 0; i < frame.size(); ++i) {
      if (frame.outliers[i]) {
        frame.points[i] = nullptr;
        frame.outliers[i] = false;
      }
    }
  }

  if (new_keyframe != nullptr && sink_ != nullptr) sink_->insertKeyFrame(new_keyframe);

  // A monocular map that is lost within its first few keyframes, or its first second, is not
  // worth keeping. (A map begun on someone walking by makes a keyframe a frame while it lasts:
  // 6 keyframes in 9 frames on a generated sequence, lost when that person's points were culled,
  // and never relocalised.) Camera time, so that the rule is the same at any frame rate.
  if (state_ == TrackingState::kLost && options_.sensor == Sensor::kMonocular && frames_lost_ > 0 &&
      !options_.localization_only) {
    std::size_t keyframes = 0;
    {
      MutexLock lock(map_.updateMutex());
      keyframes = currentMapKeyFrames();
    }
    const bool young =
        keyframes <= 5 || frame.timestamp - current_map_initialised_at_ < kYoungMapSeconds;
    if (young && !maps_started_at_.empty()) {
      // A map started after an older one was lost: the older stays; another start is tried.
      startNewMap(frame);
      record(frame, false);
      result.state = TrackingState::kLost;
      return result;
    }
    if (young) {
      spdlog::warn("map lost with only {} keyframes, {:.2f} s after it began: starting a new one",
                   keyframes, frame.timestamp - current_map_initialised_at_);
      if (sink_ != nullptr) sink_->onMapReset();
      resetMap();
      record(frame, false);
      // This frame was lost (and counted so); the next one starts the new map.
      result.state = TrackingState::kLost;
      return result;
    }
  }

  // Lost for good: relocalisation has failed for the whole of the bound.
  if (state_ == TrackingState::kLost && lost_since_ && options_.new_map_after_lost_s > 0.0 &&
      !options_.localization_only &&
      frame.timestamp - *lost_since_ >= options_.new_map_after_lost_s) {
    startNewMap(frame);
    record(frame, false);
    result.state = TrackingState::kLost;
    return result;
  }

  if (options_.report_feature_positions) reportFeaturePositions(frame, result);
  if (ok) last_frame_ = frame;
  record(frame, ok);
  result.state = state_;
  if (ok) result.T_cw = frame.T_cw;
  result.new_keyframe = new_keyframe != nullptr;
  if (new_keyframe != nullptr) result.keyframe = new_keyframe->id();
  return result;
}

bool Tracker::initialize(Frame& frame) {
  if (options_.sensor != Sensor::kMonocular) return initializeRgbd(frame);
  KeyFrame* kf = mono_init_.tryInitialize(frame, map_);
  if (kf == nullptr) {
    spdlog::debug("frame {}: not initialised: {}", frame.index, mono_init_.lastFailure());
    if (const auto refusal = mono_init_.lastRefusal()) {
      diagnostics_.refuse(*refusal, mono_init_.lastFailure());
    }
    return false;
  }
  KeyFrame* kf0 = mono_init_.referenceKeyFrame();
  {
    MutexLock lock(map_.updateMutex());
    if (new_map_start_pose_) placeNewMap(map_, *kf0, *kf, *new_map_start_pose_, frame);
    current_map_first_keyframe_ = kf0->id();
    spdlog::info("monocular map initialised at frame {} with {} points (reference frame {})",
                 frame.index, kf0->goodPoints().size(), kf0->frameIndex());
    remember(kf0);
    remember(kf);
    reference_keyframe_ = kf;
    last_keyframe_frame_ = frame.index;
    frame.reference_keyframe = kf;
    // The reference frame's own record gets its pose now that the map exists.
    for (FrameRecord& r : records_) {
      if (r.index == kf0->frameIndex()) {
        r.tracked = true;
        r.map = static_cast<std::uint32_t>(maps_started_at_.size());  // begun while lost maybe
        r.reference = kf0;
        r.T_cr = SE3d();
        r.T_cw = kf0->pose();
      }
    }
  }
  // The sink takes the map's mutex itself.
  if (sink_ != nullptr) {
    sink_->insertKeyFrame(kf0);
    sink_->insertKeyFrame(kf);
  }
  return true;
}

bool Tracker::initializeRgbd(Frame& frame) {
  if (frame.size() < static_cast<std::size_t>(options_.rgbd_init_min_features)) {
    diagnostics_.refuse(
        InitRefusal::kTooFewFeatures,
        fmt::format("{} features, need {}", frame.size(), options_.rgbd_init_min_features));
    return false;
  }
  KeyFrame* kf = nullptr;
  {
    MutexLock lock(map_.updateMutex());
    const SE3d T_cw = new_map_start_pose_.value_or(SE3d());
    const SE3d T_wc = T_cw.inverse();
    frame.T_cw = T_cw;
    kf = map_.createKeyFrame(frame.index, frame.timestamp, frame.features, T_cw);
    const FrameFeatures& f = *frame.features;
    std::vector<MapPoint*> created;
    for (std::size_t i = 0; i < frame.size(); ++i) {
      if (!f.hasDepth(i)) continue;
      const cv::Point2f& pt = f.keypoints[i].pt;
      const Eigen::Vector3d x = camera_.unproject({pt.x, pt.y}) * f.depth[i];
      MapPoint* p = map_.createMapPoint(T_wc * x, kf);
      map_.addObservation(p, kf, i);
      map_.refreshPoint(p);
      frame.points[i] = p;
      created.push_back(p);
    }
    if (created.size() < 100) {
      diagnostics_.refuse(InitRefusal::kTooFewDepthPoints,
                          fmt::format("{} keypoints with a valid depth, need 100", created.size()));
      if (maps_started_at_.empty()) {
        map_.clear();
      } else {  // the older maps stay
        for (MapPoint* p : created) map_.erasePoint(p);
        map_.eraseKeyFrame(kf);
      }
      frame.T_cw.reset();
      std::fill(frame.points.begin(), frame.points.end(), nullptr);
      return false;
    }
    current_map_first_keyframe_ = kf->id();
    spdlog::info("RGB-D map initialised at frame {} with {} points", frame.index, created.size());
    remember(kf);
  }
  reference_keyframe_ = kf;
  last_keyframe_frame_ = frame.index;
  frame.reference_keyframe = kf;
  if (sink_ != nullptr) sink_->insertKeyFrame(kf);
  return true;
}

bool Tracker::trackWithMotionModel(Frame& frame, std::size_t steps) {
  const Frame& last = *last_frame_;
  SE3d since_last;
  for (std::size_t i = 0; i < steps; ++i) since_last = *velocity_ * since_last;
  frame.T_cw = since_last * *last.T_cw;
  const bool mono = options_.sensor == Sensor::kMonocular;
  const float radius = mono ? 15.f : 7.f;
  // A prediction across lost frames is less sure: the wider window from the start.
  int matches = 0;
  for (float r = steps == 1 ? radius : 2.f * radius; r <= 2.f * radius; r *= 2.f) {
    std::fill(frame.points.begin(), frame.points.end(), nullptr);
    matches = matchByProjection(frame, last, r, mono);
    if (matches >= 20) break;
  }
  if (matches >= 20) {
    optimizeFramePose(frame);
    const int inliers = discardFrameOutliers(frame);
    spdlog::debug("frame {}: motion model over {} frames: {} matches, {} inliers", frame.index,
                  steps, matches, inliers);
    if (inliers >= options_.min_inliers_motion) return true;
  } else {
    spdlog::debug("frame {}: motion model over {} frames found {} matches", frame.index, steps,
                  matches);
  }
  std::fill(frame.points.begin(), frame.points.end(), nullptr);
  frame.T_cw.reset();
  return false;
}

bool Tracker::canRecoverByPrediction(std::size_t frame_index) const {
  return options_.recover_within_frames > 0 && velocity_ && last_frame_ && last_frame_->T_cw &&
         frame_index > last_frame_->index &&
         frame_index - last_frame_->index <= options_.recover_within_frames;
}

bool Tracker::trackReferenceKeyFrame(Frame& frame) {
  if (reference_keyframe_ == nullptr || reference_keyframe_->isBad() ||
      reference_keyframe_->isEvicted() || !last_frame_) {
    return false;
  }
  std::fill(frame.points.begin(), frame.points.end(), nullptr);
  const int matches = matchKeyFrameByDescriptor(*reference_keyframe_, frame);
  spdlog::debug("frame {}: reference keyframe matches {}", frame.index, matches);
  if (matches < 15) return false;
  frame.T_cw = last_frame_->T_cw ? *last_frame_->T_cw : reference_keyframe_->pose();
  optimizeFramePose(frame);
  return discardFrameOutliers(frame) >= options_.min_inliers_motion;
}

std::vector<KeyFrame*> Tracker::relocalizationCandidates(const Frame& frame) {
  std::vector<KeyFrame*> candidates;
  const auto add = [&](KeyFrame* kf) {
    // Evicted keyframes (bounded client map) have no features or points to match.
    if (kf != nullptr && !kf->isBad() && !kf->isEvicted() &&
        std::find(candidates.begin(), candidates.end(), kf) == candidates.end()) {
      candidates.push_back(kf);
    }
  };
  if (relocalization_hint_ != kInvalidId) {
    // The edge found the frame near this keyframe: it and its neighbours go first.
    KeyFrame* hint = map_.keyFrame(relocalization_hint_);
    if (hint != nullptr && !hint->isBad()) {
      add(hint);
      for (KeyFrame* kf : hint->bestCovisibles(kRelocalizationHintNeighbours)) add(kf);
    }
  }
  if (places_) {
    for (KeyFrameId id : places_->similar(*frame.features, options_.relocalization_candidates)) {
      add(map_.keyFrame(id));
    }
    return candidates;
  }
  // Without place recognition: the most recent keyframes and the last reference's neighbours.
  const std::vector<KeyFrame*> all = map_.keyFrames();
  for (auto it = all.rbegin(); it != all.rend() && candidates.size() < 15; ++it) add(*it);
  if (reference_keyframe_ != nullptr && !reference_keyframe_->isBad()) {
    for (KeyFrame* kf : reference_keyframe_->bestCovisibles(10)) add(kf);
  }
  return candidates;
}

bool Tracker::relocalize(Frame& frame) {
  FrameRelocalizationOptions options;
  options.budget_ms = options_.relocalization_budget_ms;
  const FrameRelocalization found =
      relocalizeFrame(frame, relocalizationCandidates(frame), places_.get(), camera_, options);
  if (found.keyframe == nullptr) return false;
  reference_keyframe_ = found.keyframe;
  relocalization_hint_ = kInvalidId;
  return true;
}

void Tracker::updateLocalMap(const Frame& frame) {
  // Keyframes that see the frame's points, weighted by how many.
  std::unordered_map<KeyFrame*, int> counter;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (p == nullptr || p->isBad()) continue;
    for (const auto& [id, obs] : p->observations()) ++counter[obs.keyframe];
  }
  local_keyframes_.clear();
  KeyFrame* best = nullptr;
  int best_count = 0;
  for (const auto& [kf, count] : counter) {
    if (kf->isBad()) continue;
    // Ties go to the newer keyframe: the map's iteration order follows addresses, which differ
    // from run to run.
    if (count > best_count || (count == best_count && best != nullptr && kf->id() > best->id())) {
      best_count = count;
      best = kf;
    }
    local_keyframes_.push_back(kf);
    kf->track_reference_for_frame = frame.index;
  }
  std::sort(local_keyframes_.begin(), local_keyframes_.end(), KeyFrameIdLess{});
  const std::size_t direct = local_keyframes_.size();
  for (std::size_t k = 0; k < direct && local_keyframes_.size() < options_.max_local_keyframes;
       ++k) {
    KeyFrame* kf = local_keyframes_[k];
    auto consider = [&](KeyFrame* other) {
      if (other == nullptr || other->isBad() || other->isEvicted() ||
          other->track_reference_for_frame == frame.index) {
        return false;
      }
      other->track_reference_for_frame = frame.index;
      local_keyframes_.push_back(other);
      return true;
    };
    for (KeyFrame* n : kf->bestCovisibles(10)) {
      if (consider(n)) break;
    }
    for (KeyFrame* c : kf->children()) {
      if (consider(c)) break;
    }
    consider(kf->parent());
  }
  if (best != nullptr) reference_keyframe_ = best;

  local_points_.clear();
  for (KeyFrame* kf : local_keyframes_) {
    for (MapPoint* p : kf->points()) {
      if (p == nullptr || p->isBad() || p->track_reference_frame == frame.index) continue;
      p->track_reference_frame = frame.index;
      local_points_.push_back(p);
    }
  }
}

int Tracker::trackLocalMap(Frame& frame) {
  updateLocalMap(frame);
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (p == nullptr) continue;
    p->increaseVisible();
    p->last_frame_seen = frame.index;
    p->track_in_view = false;
  }
  int to_match = 0;
  for (MapPoint* p : local_points_) {
    if (p->last_frame_seen == frame.index || p->isBad()) continue;
    if (isInFrustum(p, frame, 0.5f)) {
      p->increaseVisible();
      ++to_match;
    }
  }
  if (to_match > 0) {
    float radius = options_.sensor == Sensor::kRgbd ? 3.f : 1.f;
    if (relocalizations_ > 0 && frame.index < last_relocalization_frame_ + 2) radius = 5.f;
    matchLocalPoints(frame, local_points_, radius);
  }
  optimizeFramePose(frame);
  int inliers = 0;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (p == nullptr) continue;
    if (!frame.outliers[i]) {
      p->increaseFound();
      if (p->observationCount() > 0) ++inliers;
    }
  }
  return inliers;
}

KeyFrameDecision Tracker::decide(const Frame& frame, int inliers) const {
  if (reference_keyframe_ == nullptr) return KeyFrameDecision::kNo;
  KeyFrameEvidence e;
  e.frames_since_keyframe = frame.index - last_keyframe_frame_;
  e.frames_since_map_update = sink_ != nullptr
                                  ? frame.index - std::min(frame.index, sink_->lastOptimizedFrame())
                                  : e.frames_since_keyframe;
  e.keyframes_in_map = map_.keyFrameCount();
  e.frame_features = frame.size();
  e.reference_features = reference_keyframe_->size();
  e.frame_tracked = static_cast<std::size_t>(inliers);
  const int min_obs = e.keyframes_in_map <= 2 ? 2 : 3;
  e.reference_tracked = static_cast<std::size_t>(reference_keyframe_->trackedPointCount(min_obs));
  e.mapper_accepts = sink_ == nullptr || sink_->acceptsKeyFrames();
  e.mapper_accepts_urgent = sink_ == nullptr || sink_->acceptsUrgentKeyFrames();
  e.map_updates_paused = sink_ != nullptr && sink_->mapUpdatesPaused();
  // Only read while paused: not worth a pass over the reference's points on every frame.
  if (e.map_updates_paused) {
    e.reference_points = static_cast<std::size_t>(reference_keyframe_->trackedPointCount(1));
  }
  const KeyFrameDecision decision = decideKeyFrame(options_.keyframes, e);
  spdlog::debug(
      "frame {}: keyframe decision {} (since kf {}, since map update {}, kfs {}, features {}/{}, "
      "tracked {}/{}, mapper {}{})",
      frame.index, static_cast<int>(decision), e.frames_since_keyframe, e.frames_since_map_update,
      e.keyframes_in_map, e.frame_features, e.reference_features, e.frame_tracked,
      e.reference_tracked, e.mapper_accepts ? "accepts" : "busy",
      e.map_updates_paused ? ", updates paused" : "");
  return decision;
}

KeyFrame* Tracker::createKeyFrame(Frame& frame) {
  KeyFrame* kf = map_.createKeyFrame(frame.index, frame.timestamp, frame.features, *frame.T_cw);
  const FrameFeatures& f = *frame.features;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (p != nullptr && !frame.outliers[i] && !p->isBad()) map_.addObservation(p, kf, i);
  }
  if (options_.sensor != Sensor::kMonocular) {
    // New points from depth for the closest keypoints that have none (at least 100 of them).
    std::vector<std::pair<float, std::size_t>> by_depth;
    for (std::size_t i = 0; i < frame.size(); ++i) {
      if (f.hasDepth(i)) by_depth.emplace_back(f.depth[i], i);
    }
    std::sort(by_depth.begin(), by_depth.end());
    const SE3d T_wc = frame.T_cw->inverse();
    int created_or_existing = 0;
    for (const auto& [depth, i] : by_depth) {
      if (kf->point(i) == nullptr) {
        const cv::Point2f& pt = f.keypoints[i].pt;
        MapPoint* p = map_.createMapPoint(T_wc * (camera_.unproject({pt.x, pt.y}) * depth), kf);
        map_.addObservation(p, kf, i);
        map_.refreshPoint(p);
        frame.points[i] = p;
      }
      ++created_or_existing;
      if (depth > options_.close_depth_m && created_or_existing > 100) break;
    }
  }
  for (MapPoint* p : kf->goodPoints()) map_.refreshPoint(p);
  map_.updateConnections(kf);
  remember(kf);
  if (options_.triangulate_at_keyframes && options_.sensor == Sensor::kMonocular) {
    triangulateAtKeyFrame(kf, frame);
  }
  reference_keyframe_ = kf;
  last_keyframe_frame_ = frame.index;
  frame.reference_keyframe = kf;
  return kf;
}

void Tracker::triangulateAtKeyFrame(KeyFrame* keyframe, Frame& frame) {
  Stopwatch timer;
  std::size_t created = 0;
  std::size_t band_searches = 0;
  for (KeyFrame* neighbour : keyframe->bestCovisibles(options_.triangulation_neighbours)) {
    if (neighbour->isBad() || neighbour->isEvicted()) continue;
    // As local mapping: a baseline under 1 % of the scene depth triangulates nothing useful.
    const double depth = neighbour->medianSceneDepth();
    const double baseline = (neighbour->cameraCenter() - keyframe->cameraCenter()).norm();
    if (depth <= 0.0 || baseline / depth < 0.01) continue;
    const bool by_bow = canMatchForTriangulationByBow(*keyframe, *neighbour);
    if (!by_bow && ++band_searches > options_.triangulation_neighbours_without_bow) continue;
    // Without a bag of words on both sides this is the epipolar band search.
    const auto pairs = matchForTriangulationByBow(*keyframe, *neighbour, camera_, true,
                                                  options_.triangulation_ratio);
    ++triangulation_.searches;
    triangulation_.bow_searches += by_bow ? 1 : 0;
    triangulation_.pairs += pairs.size();
    for (const auto& [index, point] : createPointsFromPairs(
             map_, keyframe, neighbour, pairs, camera_, options_.min_triangulation_parallax_deg)) {
      // The next frame finds it through the last frame (motion model) and the local map.
      frame.points[index] = point;
      frame.outliers[index] = false;
      ++created;
    }
  }
  if (created > 0) map_.updateConnections(keyframe);
  triangulation_.points_created += created;
  ++triangulation_.keyframes;
  triangulation_.ms.add(timer.elapsedMs());
  spdlog::debug("keyframe {} (frame {}): {} points triangulated on the client in {:.2f} ms",
                keyframe->id(), frame.index, created, timer.elapsedMs());
}

void Tracker::reportFeaturePositions(const Frame& frame, TrackResult& result) const {
  const std::vector<cv::KeyPoint>& keypoints = frame.features->keypoints;
  result.features_on_map.reserve(keypoints.size());
  result.features_new.reserve(keypoints.size());
  for (std::size_t i = 0; i < keypoints.size(); ++i) {
    const bool on_map = i < frame.points.size() && frame.points[i] != nullptr;
    (on_map ? result.features_on_map : result.features_new).push_back(keypoints[i].pt);
  }
}

void Tracker::record(const Frame& frame, bool tracked) {
  FrameRecord r;
  r.index = frame.index;
  r.timestamp = frame.timestamp;
  r.tracked = tracked && frame.T_cw.has_value();
  r.map = static_cast<std::uint32_t>(maps_started_at_.size());
  if (r.tracked) {
    r.T_cw = *frame.T_cw;
    r.reference =
        frame.reference_keyframe != nullptr ? frame.reference_keyframe : reference_keyframe_;
    if (r.reference != nullptr) r.T_cr = r.T_cw * r.reference->poseInverse();
  }
  records_.push_back(r);
}

void Tracker::releaseErased() {
  if (last_frame_) {
    for (MapPoint*& p : last_frame_->points) {
      if (p != nullptr && p->isBad()) p = nullptr;
    }
  }
  std::erase_if(local_points_, [](const MapPoint* p) { return p->isBad(); });
  std::erase_if(local_keyframes_, [](const KeyFrame* kf) { return kf->isBad(); });
  // Erased keyframes leave the relocalisation database a few dozen at a time.
  constexpr std::size_t kForgetEvery = 32;
  if (places_ && places_->size() > map_.heldKeyFrameCount() + kForgetEvery) {
    places_->forgetIf([this](KeyFrameId id)
                          REQUIRES(map_.updateMutex()) { return map_.keyFrame(id) == nullptr; });
  }
  map_participant_.quiescent(map_);
}

void Tracker::startNewMap(const Frame& frame) {
  MutexLock lock(map_.updateMutex());
  spdlog::warn(
      "tracking lost since {:.1f} s before frame {} and not relocalised: a new map starts here "
      "(the old one is kept and merged with it when the camera sees its places again)",
      lost_since_ ? frame.timestamp - *lost_since_ : 0.0, frame.index);
  maps_started_at_.push_back(frame.index);
  if (last_frame_ && last_frame_->T_cw) new_map_start_pose_ = *last_frame_->T_cw;
  forgetTrackingState();
}

void Tracker::forgetTrackingState() {
  state_ = TrackingState::kNotInitialized;
  last_frame_.reset();
  velocity_.reset();
  reference_keyframe_ = nullptr;
  local_keyframes_.clear();
  local_points_.clear();
  frames_lost_ = 0;
  lost_since_.reset();
}

std::size_t Tracker::currentMapKeyFrames() const {
  std::size_t count = 0;
  for (const KeyFrame* kf : map_.keyFrames()) {
    if (!kf->isBad() && idOrigin(kf->id()) == idOrigin(current_map_first_keyframe_) &&
        kf->id() >= current_map_first_keyframe_) {
      ++count;
    }
  }
  return count;
}

void Tracker::resetMap() {
  MutexLock lock(map_.updateMutex());
  map_.clear();
  if (places_) places_->clear();
  for (FrameRecord& r : records_) {
    r.tracked = false;
    r.reference = nullptr;
  }
  forgetTrackingState();
  ++resets_;
  map_participant_.quiescent(map_);  // nothing of the old map is held any more
}

}  // namespace edgeslam
