#include "pipeline/local_slam.h"

#include <spdlog/spdlog.h>

#include <stdexcept>

#include "edge/movable_points.h"

namespace edgeslam {

LocalSlam::LocalSlam(const PinholeCamera& camera, SlamOptions options)
    : TrackingSlam(camera, std::move(options), 0) {
  // The session's vocabulary serves the mapper's bag-of-words triangulation search too.
  if (!options_.mapper.vocabulary) options_.mapper.vocabulary = options_.vocabulary;
  options_.mapper.thread_nice = options_.background_nice;
  mapper_ = std::make_unique<LocalMapper>(map_, camera_, options_.mapper);
  if (options_.vocabulary != nullptr && options_.loop_closing) {
    LoopCloserOptions loop = options_.loop_closer;
    const LoopCloserOptions for_sensor = loopCloserOptionsFor(options_.sensor);
    loop.verifier.fix_scale = for_sensor.verifier.fix_scale;
    loop.correction.fix_scale = for_sensor.correction.fix_scale;
    loop.threaded = options_.threaded_mapping;
    loop.thread_nice = options_.background_nice;
    loop_closer_ =
        std::make_unique<LoopCloser>(map_, camera_, options_.vocabulary, loop, mapper_.get());
    mapper_->setKeyFrameMappedCallback([this](KeyFrame* kf) { loop_closer_->insertKeyFrame(kf); });
    loop_closer_->start();
  }
  if (options_.semantic) {
    if (options_.segmenter == nullptr) {
      throw std::invalid_argument("semantic culling in local mode needs a segmenter");
    }
    segmentation_ = std::make_unique<KeyFrameSegmentationWorker>(
        options_.segmenter,
        [this](KeyFrameSegmentationResult result) { onSegmented(std::move(result)); });
  }
  startTracking(mapper_.get(), [this] {
    mapper_->waitUntilIdle();
    if (segmentation_) segmentation_->waitUntilIdle();
  });
  if (options_.threaded_mapping) mapper_->start();
}

LocalSlam::~LocalSlam() {
  if (segmentation_) segmentation_->stop();
  if (loop_closer_) loop_closer_->stop();
  mapper_->stop();
}

void LocalSlam::afterTracking(const TrackResult& result, std::size_t frame_index,
                              const cv::Mat& image) {
  if (!segmentation_ || !result.new_keyframe || result.keyframe == kInvalidId) return;
  segmentation_->submit({result.keyframe, frame_index, image.clone(),
                         cv::Size(camera_.width(), camera_.height()),
                         options_.keyframe_image_reduce});
  if (!options_.threaded_mapping) segmentation_->waitUntilIdle();
}

void LocalSlam::onSegmented(KeyFrameSegmentationResult result) {
  {
    std::lock_guard lock(map_.updateMutex());
    if (KeyFrame* keyframe = map_.keyFrame(result.keyframe)) {
      movable_points_erased_ += eraseMovablePoints(map_, *keyframe, result.labels);
    }
  }
  semantic_filter_->offerMask(result.frame_index, std::move(result.labels));
}

void LocalSlam::afterFrame() {
  if (!options_.threaded_mapping) {
    mapper_->processAll();
    if (loop_closer_) loop_closer_->processAll();
  }
  // Tracking on without a back end would report poses from a map nobody maintains.
  if (auto cause = failure()) throw std::runtime_error(*cause);
}

std::optional<std::string> LocalSlam::failure() const {
  if (auto cause = mapper_->failure()) return cause;
  if (loop_closer_) {
    if (auto cause = loop_closer_->failure()) return cause;
  }
  if (segmentation_) return segmentation_->failure();
  return std::nullopt;
}

void LocalSlam::finish() {
  if (segmentation_) segmentation_->waitUntilIdle();
  mapper_->waitUntilIdle();
  if (loop_closer_) loop_closer_->waitUntilIdle();
  if (options_.refine_intrinsics && !intrinsics_refinement_) refineIntrinsicsOfTheMap();
}

void LocalSlam::refineIntrinsicsOfTheMap() {
  // The map is complete and the mapper idle: nothing else changes it while this runs.
  spdlog::info("self-calibration over {} keyframes...", map_.keyFrameCount());
  intrinsics_refinement_ = refineMapIntrinsics(map_, camera_, options_.intrinsics_refinement);
  spdlog::info("intrinsics {}", describe(*intrinsics_refinement_));
}

SlamCounters LocalSlam::counters() const {
  SlamCounters out;
  if (loop_closer_) out.loops = loop_closer_->loops();
  addClientCounters(out);
  if (segmentation_) {
    const KeyFrameSegmentationCounters c = segmentation_->counters();
    out.keyframes_segmented = c.segmented;
    out.segmentation_ms = c.segmentation_ms;
    out.movable_points_erased = movable_points_erased_.load();
  }
  return out;
}

}  // namespace edgeslam
