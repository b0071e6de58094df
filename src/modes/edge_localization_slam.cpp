#include "modes/edge_localization_slam.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <thread>

#include "client/slice_applier.h"
#include "map/map_replication.h"

namespace edgeslam {
namespace {

SlamOptions localizationOptions(SlamOptions options) {
  options.tracker.localization_only = true;
  options.refine_intrinsics = false;  // the map is not re-solved
  options.semantic = false;           // masks come from segmented keyframes: none are made
  return options;
}

}  // namespace

EdgeLocalizationSlam::EdgeLocalizationSlam(const PinholeCamera& camera, SlamOptions options,
                                           std::unique_ptr<EdgeLink> link)
    : TrackingSlam(camera, localizationOptions(std::move(options)), link->idOrigin()),
      link_(std::move(link)) {
  link_->setSliceHandler([this](MapSlice slice) { onSlice(std::move(slice)); });
  // A question the link gave up on is never answered: without this the client would wait for it
  // and never ask again.
  link_->setUploadDroppedHandler([this](std::uint64_t sequence, KeyFrameId /*keyframe*/) {
    MutexLock lock(mutex_);
    answered_ = std::max(answered_, sequence);
  });
  startTracking(nullptr);
  tracker_->localizeInArrivingMap();
}

EdgeLocalizationSlam::~EdgeLocalizationSlam() {
  link_->close();
}

void EdgeLocalizationSlam::onSlice(MapSlice slice) {
  const SliceApplyResult applied = applySlice(map_, slice, camera_, options_.sensor);
  if (!applied.keyframes_evicted.empty() || !applied.keyframes_entered.empty()) {
    tracker_->onMapWindowChanged(applied.keyframes_evicted, applied.keyframes_entered);
  }
  MutexLock lock(mutex_);
  ++slices_applied_;
  if (slice.map_keyframes > 0) {
    map_keyframes_ = slice.map_keyframes;
    map_points_ = slice.map_points;
  }
  if (!slice.localization) return;
  const LocalizationAnswer& answer = *slice.localization;
  answered_ = std::max(answered_, slice.upload_sequence);
  answer_ms_.add(std::chrono::duration<double, std::milli>(Clock::now() - asked_at_).count());
  if (answer.T_cw) {
    ++localization_.relocalized_by_edge;
    relocalized_near_ = answer.keyframe;
    spdlog::info(
        "edge relocalised frame {} against keyframe {:#x} ({} inliers, {} candidates, {:.1f} ms "
        "on the edge); {} keyframes of the map sent",
        answer.frame_index, answer.keyframe, answer.inliers, answer.candidates, answer.edge_ms,
        slice.keyframes.size());
  } else if (answer.found) {
    ++localization_.window_moves;
  }
}

void EdgeLocalizationSlam::beforeTracking(std::size_t /*frame_index*/, const cv::Mat& /*image*/) {
  KeyFrameId near = kInvalidId;
  {
    MutexLock lock(mutex_);
    std::swap(near, relocalized_near_);
  }
  if (near != kInvalidId) tracker_->relocalizeNear(near);
}

bool EdgeLocalizationSlam::answerPending() const {
  MutexLock lock(mutex_);
  return answered_ < sequence_;
}

void EdgeLocalizationSlam::afterTracking(const TrackResult& result, std::size_t frame_index,
                                         const cv::Mat& /*image*/) {
  if (answerPending()) return;  // one question at a time
  if (result.state == TrackingState::kOk) {
    const std::vector<Tracker::FrameRecord>& records = tracker_->records();
    const KeyFrame* reference = records.empty() ? nullptr : records.back().reference;
    if (reference == nullptr || reference->id() == window_centre_) return;
    window_centre_ = reference->id();
  }
  ask(frame_index, result);
  // Frames fed back to back: a lost frame's answer is waited for, as a camera's pace would give
  // it time to come, so that the map window is there for the next frame.
  if (options_.wait_for_backend && result.state != TrackingState::kOk) waitForAnswer();
}

void EdgeLocalizationSlam::ask(std::size_t frame_index, const TrackResult& result) {
  KeyFrameUpload upload;
  upload.sequence = ++sequence_;
  upload.localization_query = true;
  KeyFrameRecord& frame = upload.keyframe;
  frame.id = map_.ids().next();
  frame.frame_index = frame_index;
  const std::vector<Tracker::FrameRecord>& records = tracker_->records();
  if (!records.empty()) frame.timestamp = records.back().timestamp;
  if (result.state == TrackingState::kOk && result.T_cw) {
    frame.T_cw = *result.T_cw;
    frame.parent = window_centre_;
  } else {
    frame.features = featuresRecord(*lastFrameFeatures());
    frame.point_ids.assign(frame.features.keypoints.size(), kInvalidId);
  }
  {
    MutexLock lock(mutex_);
    asked_at_ = Clock::now();
    ++localization_.queries;
    if (frame.parent == kInvalidId) ++localization_.relocalization_queries;
  }
  link_->send(std::move(upload));
}

void EdgeLocalizationSlam::waitForAnswer() {
  const Clock::time_point start = Clock::now();
  while (answerPending()) {
    if (Clock::now() - start > std::chrono::duration<double>(max_answer_wait_s)) {
      spdlog::warn("edge: localisation question unanswered after {:.0f} s; tracking goes on",
                   max_answer_wait_s);
      MutexLock lock(mutex_);
      answered_ = sequence_;  // given up on: the next lost frame asks again
      return;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
}

void EdgeLocalizationSlam::finish() {
  waitForAnswer();
}

std::size_t EdgeLocalizationSlam::keyFrameCount() const {
  MutexLock lock(mutex_);
  return map_keyframes_;
}

std::size_t EdgeLocalizationSlam::mapPointCount() const {
  MutexLock lock(mutex_);
  return map_points_;
}

LinkTraffic EdgeLocalizationSlam::linkTraffic() const {
  const EdgeLinkCounters link = link_->counters();
  return {link.uplink_bytes, link.downlink_bytes};
}

SlamCounters EdgeLocalizationSlam::counters() const {
  const EdgeLinkCounters link = link_->counters();
  SlamCounters out;
  out.exchange.uplink_bytes = link.uplink_bytes;
  out.exchange.downlink_bytes = link.downlink_bytes;
  out.exchange.uploads_dropped = link.uploads_dropped;
  out.exchange.reconnects = link.reconnects;
  addClientCounters(out);
  MutexLock lock(mutex_);
  out.exchange.keyframes_uploaded = localization_.queries;
  out.exchange.slices_applied = slices_applied_;
  out.localization = localization_;
  out.localization.answer_ms = answer_ms_.summary();
  return out;
}

}  // namespace edgeslam
