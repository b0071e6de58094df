#include "modes/edge_slam.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <mutex>
#include <thread>
#include <unordered_set>

#include "client/frame_rate_scaling.h"
#include "client/slice_applier.h"
#include "semantic/label_encoding.h"

namespace edgeslam {

EdgeSlam::EdgeSlam(const PinholeCamera& camera, SlamOptions options, std::unique_ptr<EdgeLink> link,
                   std::optional<AdaptationLoopOptions> adaptation)
    : TrackingSlam(camera, std::move(options), link->idOrigin()), link_(std::move(link)) {
  EdgeKeyFrameSinkOptions sink_options;
  sink_options.camera = camera_;
  // The edge resumed a stored map holding ids of this origin: ours start above them.
  if (link_->idFloor() != 0) map_.ids().advancePast(link_->idFloor());
  own_id_origin_ = link_->idOrigin();
  own_ids_above_ = link_->idFloor();
  sink_ = std::make_unique<EdgeKeyFrameSink>(map_, *link_, sink_options);
  link_->setSliceHandler([this](MapSlice slice) { onSlice(std::move(slice)); });
  link_->setUploadDroppedHandler(
      [this](std::uint64_t sequence, KeyFrameId keyframe) { onUploadDropped(sequence, keyframe); });
  options_.tracker.triangulate_at_keyframes = options_.client_triangulation;
  startTracking(sink_.get(), [this] { waitForEdge(); });
  if (adaptation && link_->edgeClient() != nullptr) {
    adaptation_ = std::make_unique<AdaptationLoop>(*link_->edgeClient(), *adaptation);
    adaptation_->start();
  }
}

EdgeSlam::~EdgeSlam() {
  if (adaptation_) adaptation_->stop();  // it probes through the link's client
  link_->close();
  const KeyFrameTriangulationStats& t = tracker_->triangulationStats();
  if (t.keyframes > 0) {
    const PercentileSummary ms = t.ms.summary();
    spdlog::info(
        "client triangulation: {} keyframes, {} searches ({} by bag of words), {} pairs, {} points "
        "created; {:.2f} ms median, {:.2f} ms p90, {:.2f} ms max per keyframe",
        t.keyframes, t.searches, t.bow_searches, t.pairs, t.points_created, ms.median, ms.p90,
        ms.max);
  }
}

void EdgeSlam::beforeTracking(std::size_t frame_index, const cv::Mat& image) {
  if (semantic_filter_) sink_->attachImage(frame_index, image);
}

void EdgeSlam::noteClientMapSize(std::size_t keyframes, std::size_t points) {
  MutexLock lock(stats_mutex_);
  client_map_.keyframes = keyframes;
  client_map_.points = points;
  client_map_.max_keyframes = std::max(client_map_.max_keyframes, keyframes);
  client_map_.max_points = std::max(client_map_.max_points, points);
}

const KeyFrameTriangulationStats& EdgeSlam::clientTriangulation() const {
  return tracker_->triangulationStats();
}

ClientMapSize EdgeSlam::clientMapSize() const {
  std::size_t keyframes = 0, points = 0;
  {
    MutexLock lock(map_.updateMutex());
    keyframes = map_.heldKeyFrameCount();
    points = map_.pointCount();
  }
  MutexLock lock(stats_mutex_);
  ClientMapSize out = client_map_;
  out.keyframes = keyframes;
  out.points = points;
  out.max_keyframes = std::max(out.max_keyframes, keyframes);
  out.max_points = std::max(out.max_points, points);
  return out;
}

std::size_t EdgeSlam::keyFrameCount() const {
  {
    MutexLock lock(stats_mutex_);
    if (edge_map_keyframes_ > 0) return edge_map_keyframes_;
  }
  return TrackingSlam::keyFrameCount();
}

std::size_t EdgeSlam::mapPointCount() const {
  {
    MutexLock lock(stats_mutex_);
    if (edge_map_points_ > 0) return edge_map_points_;
  }
  return TrackingSlam::mapPointCount();
}

void EdgeSlam::onUploadDropped(std::uint64_t sequence, KeyFrameId keyframe) {
  // May run on the tracking thread inside track() (an upload pushed out of the link's full
  // queue): the tracker hears of it after the frame.
  if (!sink_->onUploadDropped(sequence, keyframe)) return;
  MutexLock lock(stats_mutex_);
  forgotten_keyframes_.push_back(keyframe);
}

void EdgeSlam::afterTracking(const TrackResult& result, std::size_t /*frame_index*/,
                             const cv::Mat& /*image*/) {
  // --fast: the next frame is tracked with the edge's answer to this keyframe (its points, its
  // local BA) applied, as a camera-paced run sees it when the slice comes within a frame's period.
  // Fed back to back, frames ran ~5 ahead of the slice: KITTI 07 mono lost the road at frame 49 in
  // 3 runs of 5 (with only the client's own points of the last keyframes), a paced run in none.
  if (result.new_keyframe && result.keyframe != kInvalidId) {
    waitForBackend([this] { waitForEdge(); });
  }
}

void EdgeSlam::afterFrame() {
  std::vector<KeyFrameId> forgotten;
  std::vector<KeyFrameId> resend;
  {
    MutexLock lock(stats_mutex_);
    forgotten.swap(forgotten_keyframes_);
    resend.swap(keyframes_to_resend_);
  }
  if (!forgotten.empty()) tracker_->onMapWindowChanged(forgotten, {});
  if (!resend.empty()) {
    std::uint64_t resent = 0;
    for (const KeyFrameId id : resend) resent += sink_->resendKeyFrame(id) ? 1 : 0;
    spdlog::info("edge: {} keyframes the edge lacked after its restart uploaded again", resent);
    MutexLock lock(stats_mutex_);
    resync_.keyframes_resent += resent;
  }
  {
    // Tracking adds keyframes and points between slices: the client map's peak is seen here.
    // Not worth waiting for a slice being applied (it notes the size itself when done).
    if (map_.updateMutex().try_lock()) {
      const std::size_t keyframes = map_.heldKeyFrameCount();
      const std::size_t points = map_.pointCount();
      map_.updateMutex().unlock();
      noteClientMapSize(keyframes, points);
    }
  }
  if (!adaptation_) return;
  adaptation_->onFrame();  // counted under the configuration this frame ran with
  const std::uint64_t version = adaptation_->version();
  if (version != applied_config_version_) {
    applied_config_version_ = version;
    applyConfiguration(adaptation_->current());
  }
  const std::uint64_t uploads = sink_->uploadsSent();
  if (uploads != uploads_seen_ && uploads > 0) {
    uploads_seen_ = uploads;
    // Probes are counted by the link before the adaptation loop counts them, so reading the
    // loop's count first keeps it within the link's: the other order raced with a probe in flight
    // and gave a negative size.
    const double probes = static_cast<double>(adaptation_->counters().probe_uplink_bytes);
    const double uplink = static_cast<double>(link_->counters().uplink_bytes);
    if (uplink > probes)
      adaptation_->setMessageBytes((uplink - probes) / static_cast<double>(uploads));
  }
}

void EdgeSlam::applyConfiguration(const KeyframeConfig& config) {
  KeyFrameParameters& kf = tracker_->keyframeParameters();
  setKeyFrameGaps(kf, config.fmin, config.fmax, camera_.intrinsics().fps);
  kf.alpha = config.alpha;
  kf.beta = config.beta;
  setPyramidLevels(config.pyramid_levels);
  sink_->setSegmenterNms(static_cast<float>(config.nms_threshold));
  spdlog::info(
      "adaptation: keyframes fmin {} fmax {} alpha {} beta {}, {} pyramid levels, segmenter nm {}",
      kf.fmin, kf.fmax, kf.alpha, kf.beta, config.pyramid_levels, config.nms_threshold);
}

void EdgeSlam::onSlice(MapSlice slice) {
  Stopwatch apply_timer;
  const SliceApplyResult applied = applySlice(map_, slice, camera_, options_.sensor);
  if (tracker_ && (!applied.keyframes_evicted.empty() || !applied.keyframes_entered.empty())) {
    tracker_->onMapWindowChanged(applied.keyframes_evicted, applied.keyframes_entered);
  }
  const double apply_ms = apply_timer.elapsedMs();
  noteClientMapSize(applied.keyframes_held, applied.points_held);
  spdlog::debug(
      "slice {} (keyframe of frame {}): {} points written, {} erased, {} poses, {} keyframes "
      "evicted ({} points), {} back, {:.1f} ms",
      slice.sequence, applied.frame_index, applied.points_upserted, applied.points_erased,
      applied.keyframes_moved, applied.keyframes_evicted.size(), applied.points_evicted,
      applied.keyframes_entered.size(), apply_ms);
  const double latency_s = sink_->onSliceApplied(slice.upload_sequence, applied.frame_index);
  if (slice.full_resync) onFullResync(applied.keyframes_edge_lacks);
  for (const MaskRecord& mask : slice.masks) offerMask(mask);
  MutexLock lock(stats_mutex_);
  ++slices_applied_;
  loops_ += slice.loops_closed;
  merges_ += slice.maps_merged;
  loop_frames_.insert(loop_frames_.end(), slice.loops.begin(), slice.loops.end());
  if (slice.maps_merged > 0) {
    spdlog::info("the edge merged the map this client is in onto another part (slice {})",
                 slice.sequence);
    // The edge moves the part without the map's origin, so the other part is an older one: taken
    // to be the first map's (a client with two maps started after losses, merged onto each
    // other first, is not told apart).
    first_map_frame_.currentMapJoinedFirst();
  }
  if (slice.map_keyframes > 0 || slice.map_points > 0) {
    edge_map_keyframes_ = slice.map_keyframes;
    edge_map_points_ = slice.map_points;
  }
  for (const KeyFrameId id : applied.erased_keyframe_ids) {
    if ((id >> 56) == own_id_origin_ && id > own_ids_above_) ++resync_.keyframes_culled_by_edge;
  }
  client_map_.keyframes_evicted += applied.keyframes_evicted.size();
  client_map_.keyframes_entered += applied.keyframes_entered.size();
  slice_apply_ms_.add(apply_ms);
  if (latency_s >= 0.0) slice_latency_ms_.add(latency_s * 1000.0);
}

void EdgeSlam::onFullResync(const std::vector<KeyFrameId>& edge_lacks) {
  // Those still in the link's queue are on their way; the others the edge lost.
  const std::vector<KeyFrameId> pending = link_->pendingKeyFrames();
  const std::unordered_set<KeyFrameId> on_the_way(pending.begin(), pending.end());
  std::vector<KeyFrameId> resend;
  std::uint64_t lost_evicted = 0;
  {
    MutexLock lock(map_.updateMutex());
    for (const KeyFrameId id : edge_lacks) {
      const KeyFrame* keyframe = map_.keyFrame(id);
      if (keyframe == nullptr || keyframe->isBad() || on_the_way.contains(id)) continue;
      if (keyframe->isEvicted()) {
        ++lost_evicted;
      } else {
        resend.push_back(id);
      }
    }
  }
  spdlog::warn(
      "edge: full resync: the edge's map lacks {} of this client's keyframes: {} to upload again, "
      "{} lost (evicted here before the edge stored them), {} still on their way",
      edge_lacks.size(), resend.size(), lost_evicted,
      edge_lacks.size() - resend.size() - lost_evicted);
  MutexLock lock(stats_mutex_);
  ++resync_.full_resyncs;
  resync_.keyframes_lost_evicted += lost_evicted;
  keyframes_to_resend_.insert(keyframes_to_resend_.end(), resend.begin(), resend.end());
}

ResyncCounters EdgeSlam::resyncCounters() const {
  MutexLock lock(stats_mutex_);
  return resync_;
}

void EdgeSlam::offerMask(const MaskRecord& mask) {
  {
    MutexLock lock(stats_mutex_);
    ++keyframes_segmented_;
    segmentation_ms_.add(mask.segmentation_ms);
  }
  if (!semantic_filter_) return;
  std::size_t frame_index = 0;
  {
    MutexLock lock(map_.updateMutex());
    const KeyFrame* keyframe = map_.keyFrame(mask.keyframe);
    if (keyframe == nullptr) return;  // culled meanwhile: its mask is of no use any more
    frame_index = keyframe->frameIndex();
  }
  try {
    semantic_filter_->offerMask(
        frame_index,
        decodeLabelImage(mask.bytes, mask.encoding, cv::Size(camera_.width(), camera_.height())));
  } catch (const std::exception& e) {
    spdlog::warn("mask of the keyframe of frame {} ignored: {}", frame_index, e.what());
  }
}

void EdgeSlam::waitForEdge() {
  // Bounded: an edge that stopped answering must not hang tracking (the link drops its uploads
  // in time, which also ends the wait).
  Stopwatch waited;
  while (!sink_->allAnswered()) {
    if (waited.elapsedMs() > kMaxEdgeWaitS * 1000.0) {
      spdlog::warn("edge: keyframe upload unanswered after {:.0f} s; tracking goes on",
                   kMaxEdgeWaitS);
      return;
    }
    std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
}

void EdgeSlam::finish() {
  if (adaptation_) adaptation_->stop();
  Stopwatch waited;
  while (!sink_->allAnswered()) {
    if (waited.elapsedMs() > finish_timeout_s * 1000.0) {
      spdlog::warn("edge: {} keyframe uploads still unanswered after {:.0f} s",
                   sink_->uploadsSent() - sink_->uploadsAnswered(), finish_timeout_s);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

LinkTraffic EdgeSlam::linkTraffic() const {
  const EdgeLinkCounters link = link_->counters();
  return {link.uplink_bytes, link.downlink_bytes};
}

SlamCounters EdgeSlam::counters() const {
  const EdgeLinkCounters link = link_->counters();
  SlamCounters out;
  out.exchange.uplink_bytes = link.uplink_bytes;
  out.exchange.downlink_bytes = link.downlink_bytes;
  out.exchange.uploads_dropped = link.uploads_dropped;
  out.exchange.uploads_overflowed = link.uploads_overflowed;
  out.exchange.keyframes_forgotten = sink_->keyFramesForgotten();
  out.exchange.points_forgotten = sink_->pointsForgotten();
  out.exchange.reconnects = link.reconnects;
  out.exchange.keyframes_uploaded = sink_->uploadsSent();
  out.exchange.uploads_unanswered = sink_->uploadsInFlight();
  MutexLock lock(stats_mutex_);
  out.exchange.slices_applied = slices_applied_;
  out.map.loops = loops_;
  out.map.merges = merges_;
  out.map.loop_frames = loop_frames_;
  out.exchange.slice_latency_ms = slice_latency_ms_.summary();
  out.exchange.slice_apply_ms = slice_apply_ms_.summary();
  out.semantic.keyframes_segmented = keyframes_segmented_;
  out.semantic.segmentation_ms = segmentation_ms_.summary();
  addClientCounters(out);
  return out;
}

}  // namespace edgeslam
