#include "server/edge_map_session.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "map/map_replication.h"
#include "semantic/label_encoding.h"
#include "server/omitted_descriptors.h"
#include "server/slice_builder.h"
#include "util/timing_stats.h"

namespace edgeslam {

MappingBackendOptions edgeSessionBackendOptions() {
  MappingBackendOptions options;
  options.thread_nice_when_segmenting = 10;
  return options;
}

EdgeMapSession::EdgeMapSession(const PinholeCamera& camera, Sensor sensor,
                               EdgeMapSessionOptions options, Publish publish)
    : camera_(camera),
      mask_downscale_(std::max(1, options.mask_downscale)),
      publish_(std::move(publish)),
      window_(options.window) {
  MappingBackendHooks hooks;
  hooks.keyframe_mapped = [this](KeyFrame* keyframe) { publishSlice(keyframe); };
  hooks.map_corrected = [this] { publishSlice(nullptr); };
  hooks.keyframe_segmented = [this](KeyFrameSegmentationResult result) {
    onSegmented(std::move(result));
  };
  backend_ = std::make_unique<MappingBackend>(map_, camera_, sensor, std::move(options.backend),
                                              std::move(hooks));
  if (options.preload) options.preload(map_);
  adoptPreloadedMap();
  backend_->start();
}

void EdgeMapSession::adoptPreloadedMap() {
  std::vector<KeyFrame*> loaded;
  KeyFrameId newest = kInvalidId;
  {
    MutexLock lock(map_.updateMutex());
    for (KeyFrame* keyframe : map_.keyFrames()) {
      if (keyframe->isBad()) continue;
      loaded.push_back(keyframe);
      window_.clientHolds(keyframe->id());
      newest = std::max(newest, keyframe->id());
    }
  }
  if (loaded.empty()) return;
  // Before the threads start: nothing else touches the keyframes' places or the loop database.
  Stopwatch timer;
  backend_->adoptLoadedKeyFrames(loaded);
  MutexLock state(state_mutex_);
  newest_keyframe_ = newest;
  stats_.keyframes_loaded = loaded.size();
  stats_.load_describe_ms = timer.elapsedMs();
  stats_.keyframes = loaded.size();
}

EdgeMapSession::~EdgeMapSession() {
  stop();
  const EdgeMapSessionStats totals = stats();
  if (totals.descriptors_filled + totals.descriptors_lost > 0) {
    spdlog::info(
        "edge session: {} uploaded keypoints took their map point's descriptor, {} lost theirs "
        "(point gone)",
        totals.descriptors_filled, totals.descriptors_lost);
  }
}

void EdgeMapSession::stop() {
  backend_->stop();
}

void EdgeMapSession::onKeyFrame(const KeyFrameUpload& upload) {
  cv::Mat image;
  if (backend_->segments() && !upload.image_bytes.empty()) {
    image = cv::imdecode(upload.image_bytes, cv::IMREAD_UNCHANGED);
    if (image.empty() || (image.type() != CV_8UC1 && image.type() != CV_8UC3)) {
      throw std::invalid_argument("keyframe image (" + upload.image_encoding + ", " +
                                  std::to_string(upload.image_bytes.size()) +
                                  " bytes) is not an 8-bit grey or colour image");
    }
  }
  KeyFrame* keyframe = nullptr;
  {
    MutexLock lock(map_.updateMutex());
    if (!upload.map_reset && map_.keyFrame(upload.keyframe.id) != nullptr) {
      // Re-sent after a full resync while its first upload was still on its way, or sent to a
      // server that stored it before a restart: the map has it. The client waits for an answer.
      lock.unlock();
      {
        MutexLock state(state_mutex_);
        ++stats_.uploads_duplicate;
      }
      publishSlice(nullptr, upload.sequence);
      return;
    }
    if (upload.map_reset) {
      backend_->onMapReset();
      map_.clear();
      if (observer_ != nullptr) observer_->onMapCleared();
      window_.clear();
      window_centre_ = kInvalidId;
    }
    // Descriptors the wire left out are those of points this map has (or had).
    const KeyFrameRecord* record = &upload.keyframe;
    KeyFrameRecord filled;
    OmittedDescriptorFill fill;
    if (!upload.keyframe.features.descriptor_omitted.empty()) {
      filled = upload.keyframe;
      fill = fillOmittedDescriptors(map_, filled);
      record = &filled;
      if (!fill.lost.empty()) {
        spdlog::debug(
            "keyframe {:#x}: {} keypoints name points this map no longer has and came without "
            "descriptors: they keep neither (first: keypoint {})",
            filled.id, fill.lost.size(), fill.lost.front());
      }
    }
    // The client already has what it sent: apply it without recording it for the slices.
    map_.setChangeRecording(false);
    std::vector<UploadedPointConflict> conflicts;
    try {
      std::vector<MapPointRecord> new_points = upload.new_points;
      rebuildPositionsFromDepth(new_points, *record, camera_);
      keyframe = insertKeyFrameRecord(map_, *record, camera_);
      for (const MapPointRecord& point : new_points) {
        if (map_.mapPoint(point.id) != nullptr) continue;
        // Normal, descriptor and distance range follow from the observations: the upload need
        // not carry them.
        if (auto conflict = insertUploadedPoint(map_, point, upload.keyframe.id)) {
          conflicts.push_back(*conflict);
        }
      }
    } catch (...) {
      map_.setChangeRecording(true);
      throw;
    }
    map_.setChangeRecording(true);
    // Where the edge's map differs from what the client sent, the slices say so.
    resolveUploadedPointConflicts(map_, conflicts);
    if (observer_ != nullptr) {
      // Applied without recording (the client has it): the observer still needs all of it.
      MapChanges uploaded;
      uploaded.keyFrameCreated(keyframe->id());
      for (const MapPoint* point : keyframe->points()) {
        if (point != nullptr) uploaded.pointUpdated(point->id());
      }
      observer_->onMapChanged(uploaded);
    }
    window_.clientHolds(keyframe->id());
    MutexLock state(state_mutex_);
    ++stats_.uploads;
    stats_.descriptors_filled += fill.filled;
    stats_.descriptors_lost += fill.lost.size();
    upload_of_keyframe_[keyframe->id()] = upload.sequence;
    newest_keyframe_ = keyframe->id();
  }
  if (upload.segmenter_nms > 0.f) backend_->setNmsThreshold(upload.segmenter_nms);
  if (!image.empty()) {
    backend_->segment({keyframe->id(), keyframe->frameIndex(), std::move(image),
                       cv::Size(camera_.width(), camera_.height())});
  }
  backend_->insertKeyFrame(keyframe);
  backend_->processAll();
}

void EdgeMapSession::publishSlice(KeyFrame* mapped, std::uint64_t answers) {
  MutexLock publishing(publish_mutex_);
  MapSlice slice;
  {
    MutexLock lock(map_.updateMutex());
    const std::size_t loops = backend_->loops();
    std::vector<MaskRecord> masks;
    {
      MutexLock state(state_mutex_);
      masks.swap(pending_masks_);
    }
    if (mapped == nullptr && answers == 0 && map_.changes().empty() && loops == loops_published_ &&
        masks.empty()) {
      return;
    }
    MapChanges changes = map_.takeChanges();
    if (observer_ != nullptr) {
      observer_->onMapChanged(changes);
      if (!masks.empty()) observer_->onMasks(masks);
    }
    slice = buildSlice(map_, changes);
    // A keyframe culled as soon as it was mapped (a revisit) hands the window to the keyframe it
    // hangs from in the spanning tree, near where the camera is.
    KeyFrame* centre = mapped;
    while (centre != nullptr && centre->isBad()) centre = centre->parent();
    if (centre != nullptr) window_centre_ = centre->id();
    // Loop corrections and global BA keep the window of the last mapped keyframe.
    const std::size_t entering_before = slice.keyframes.size();
    window_.shape(map_, map_.keyFrame(window_centre_), slice);
    slice.map_keyframes = map_.keyFrameCount();
    slice.map_points = map_.pointCount();
    slice.masks = std::move(masks);
    if (mapped != nullptr) {
      slice.processed_keyframe = mapped->id();
      if (!mapped->isBad()) {
        slice.reference_keyframe = mapped->id();
        slice.reference_pose = mapped->pose();
      }
    }
    slice.loops_closed = static_cast<std::uint32_t>(loops - loops_published_);
    loops_published_ = loops;
    MutexLock state(state_mutex_);
    slice.sequence = ++slice_sequence_;
    // A correction answers no upload.
    // The slice answers the upload of the keyframe it mapped (later uploads may be queued).
    slice.upload_sequence = answers;
    if (mapped != nullptr) {
      const auto it = upload_of_keyframe_.find(mapped->id());
      if (it != upload_of_keyframe_.end()) {
        slice.upload_sequence = it->second;
        upload_of_keyframe_.erase(it);
      }
    }
    slice.newest_keyframe = newest_keyframe_;
    ++stats_.slices;
    if (window_.bounded()) {
      stats_.client_keyframes_held = window_.held().size();
      stats_.client_keyframes_evicted += slice.keyframes_evicted.size();
      stats_.client_keyframes_resent += slice.keyframes.size() - entering_before;
    }
    stats_.keyframes = map_.keyFrameCount();
    stats_.map_points = map_.pointCount();
  }
  if (publish_) publish_(std::move(slice));
}

void EdgeMapSession::publishFullResync() {
  MutexLock publishing(publish_mutex_);
  MapSlice slice;
  {
    MutexLock lock(map_.updateMutex());
    // What changed since the last slice is in the whole map sent now; the store still needs it.
    MapChanges changes = map_.takeChanges();
    if (observer_ != nullptr) observer_->onMapChanged(changes);
    slice.full_resync = true;
    for (const KeyFrame* keyframe : map_.keyFrames()) {
      if (keyframe->isBad()) continue;
      slice.keyframe_poses.push_back(keyFramePoseRecord(*keyframe));
    }
    for (const MapPoint* point : map_.mapPoints()) {
      if (!point->isBad()) slice.points_upserted.push_back(mapPointRecord(*point));
    }
    // Points are attached only to keyframes the client holds; a bounded client ignores the rest.
    slice.map_keyframes = map_.keyFrameCount();
    slice.map_points = map_.pointCount();
    const std::size_t loops = backend_->loops();
    slice.loops_closed = static_cast<std::uint32_t>(loops - loops_published_);
    loops_published_ = loops;
    MutexLock state(state_mutex_);
    slice.sequence = ++slice_sequence_;
    // newest_keyframe stays unset: the client must not drop observations in its own keyframes
    // that the edge lacks (it re-sends those keyframes).
    ++stats_.slices;
    ++stats_.full_resyncs;
  }
  if (publish_) publish_(std::move(slice));
}

void EdgeMapSession::onSegmented(KeyFrameSegmentationResult result) {
  // The back end has erased the keyframe's movable points; the mask goes to the client with them.
  MaskRecord mask;
  mask.keyframe = result.keyframe;
  mask.bytes = encodeLabelImage(result.labels, mask_downscale_, mask.encoding);
  mask.width = (result.labels.cols + mask_downscale_ - 1) / mask_downscale_;
  mask.height = (result.labels.rows + mask_downscale_ - 1) / mask_downscale_;
  mask.segmentation_ms = result.segmentation_ms;
  {
    MutexLock state(state_mutex_);
    pending_masks_.push_back(std::move(mask));
  }
  publishSlice(nullptr);
}

void EdgeMapSession::setNmsThreshold(float nm) {
  backend_->setNmsThreshold(nm);
}

void EdgeMapSession::finish() {
  backend_->waitUntilIdle();
}

std::optional<std::string> EdgeMapSession::failure() const {
  return backend_->failure();
}

EdgeMapSessionStats EdgeMapSession::stats() const {
  const MappingBackendCounters backend = backend_->counters();
  MutexLock state(state_mutex_);
  EdgeMapSessionStats out = stats_;
  out.keyframes_segmented = backend.keyframes_segmented;
  out.movable_points_erased = backend.movable_points_erased;
  return out;
}

}  // namespace edgeslam
