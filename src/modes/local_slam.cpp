#include "modes/local_slam.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

#include "mapping/map_part_merge.h"

namespace edgeslam {

LocalSlam::LocalSlam(const PinholeCamera& camera, SlamOptions options)
    : TrackingSlam(camera, std::move(options), 0) {
  MappingBackendOptions backend = options_.backend;
  if (options_.semantic) {
    if (backend.segmenter == nullptr) {
      throw std::invalid_argument("semantic culling in local mode needs a segmenter");
    }
  } else {
    backend.segmenter = nullptr;
  }
  MappingBackendHooks hooks;
  hooks.keyframe_segmented = [this](KeyFrameSegmentationResult result) {
    semantic_filter_->offerMask(result.frame_index, std::move(result.labels));
  };
  // Told under the map's update mutex (held by the loop closer).
  hooks.parts_merged = [this](const MapPartMerge& merge) NO_THREAD_SAFETY_ANALYSIS {
    if (!merge.moved_current_side || merge.moved.empty()) return;
    KeyFrame* origin = map_.originKeyFrame();
    KeyFrame* moved = map_.keyFrame(merge.moved.front());
    if (origin != nullptr && moved != nullptr && connectedPart(moved).contains(origin)) {
      first_map_frame_.currentMapJoinedFirst();
    }
  };
  backend_ = std::make_unique<MappingBackend>(map_, camera_, options_.sensor, std::move(backend),
                                              std::move(hooks));
  startTracking(backend_.get(), [this] { backend_->waitUntilKeyFramesMapped(); });
  backend_->start();
}

LocalSlam::~LocalSlam() {
  backend_->stop();
}

void LocalSlam::beforeCulling(std::size_t frame_index, const cv::Mat& image) {
  // A map with depth is begun on the first frame that has enough of it: a frame with its people
  // unmasked puts them into the first keyframe, and at the camera's pace the next dozen frames are
  // tracked against them before any mask is back (report-10: the path over frames 0-19 came out
  // 5-7x the true one). So that frame waits for its own mask, whatever the pacing: a camera
  // started ~60 ms late.
  if (first_frame_mask_awaited_ || options_.sensor == Sensor::kMonocular || !backend_->segments() ||
      tracker_->state() != TrackingState::kNotInitialized) {
    return;
  }
  first_frame_mask_awaited_ = true;
  submitSegmentation(kInvalidId, frame_index, image);
  backend_->waitUntilSegmented();
}

void LocalSlam::afterTracking(const TrackResult& result, std::size_t frame_index,
                              const cv::Mat& image) {
  if (!backend_->segments()) return;
  if (result.state == TrackingState::kNotInitialized) {
    // No keyframe before the map exists: a frame every refresh interval is segmented instead, so
    // that a monocular map is begun on frames whose people are masked.
    if (frame_index < next_frame_to_segment_before_the_map_) return;
    const int refresh = tracker_->keyframeParameters().segmentation_refresh;
    next_frame_to_segment_before_the_map_ =
        frame_index + static_cast<std::size_t>(std::max(1, refresh));
    segmentAndWaitWhenFast(kInvalidId, frame_index, image);
  } else if (result.new_keyframe && result.keyframe != kInvalidId) {
    segmentAndWaitWhenFast(result.keyframe, frame_index, image);
  }
}

void LocalSlam::submitSegmentation(KeyFrameId keyframe, std::size_t frame_index,
                                   const cv::Mat& image) {
  backend_->segment({keyframe, frame_index, image.clone(),
                     cv::Size(camera_.width(), camera_.height()), options_.keyframe_image_reduce});
}

void LocalSlam::segmentAndWaitWhenFast(KeyFrameId keyframe, std::size_t frame_index,
                                       const cv::Mat& image) {
  submitSegmentation(keyframe, frame_index, image);
  // Frames fed back to back (--fast) would otherwise get a keyframe's mask as many frames late as
  // they are faster than segmentation (8-10 frames, where a camera at 30 fps sees it 2 frames
  // late), and the mask transfer would pay for a speed that is the host's, not the camera's. So
  // the next frame waits for it: at --fast the mask is one frame late whatever the host.
  waitForBackend([this] { backend_->waitUntilSegmented(); });
}

void LocalSlam::afterFrame() {
  backend_->processAll();  // unthreaded (--deterministic): the back end runs here
  // Tracking on without a back end would report poses from a map nobody maintains.
  if (auto cause = failure()) throw std::runtime_error(*cause);
}

std::optional<std::string> LocalSlam::failure() const {
  return backend_->failure();
}

void LocalSlam::finish() {
  backend_->waitUntilIdle();
  if (options_.refine_intrinsics && !intrinsics_refinement_) refineIntrinsicsOfTheMap();
}

void LocalSlam::refineIntrinsicsOfTheMap() {
  // The map is complete and the mapper idle: nothing else changes it while this runs.
  std::size_t keyframes = 0;
  {
    MutexLock lock(map_.updateMutex());
    keyframes = map_.keyFrameCount();
  }
  spdlog::info("self-calibration over {} keyframes...", keyframes);
  intrinsics_refinement_ = refineMapIntrinsics(map_, camera_, options_.intrinsics_refinement);
  spdlog::info("intrinsics {}", describe(*intrinsics_refinement_));
}

SlamCounters LocalSlam::counters() const {
  SlamCounters out;
  const MappingBackendCounters backend = backend_->counters();
  out.map.loops = backend.loops;
  out.map.merges = backend.merges;
  if (const LoopCloser* closer = backend_->loopCloser(); closer != nullptr) {
    for (const LoopEvent& event : closer->eventsFrom(0)) {
      out.map.loop_frames.push_back({event.current_frame, event.loop_frame});
    }
  }
  addClientCounters(out);
  if (backend_->segments()) {
    out.semantic.keyframes_segmented = backend.keyframes_segmented;
    out.semantic.keyframes_not_segmented = backend.keyframes_not_segmented;
    out.semantic.segmentation_ms = backend.segmentation_ms;
    out.semantic.movable_points_erased = backend.movable_points_erased;
  }
  return out;
}

}  // namespace edgeslam
