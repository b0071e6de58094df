#include "mapping/mapping_backend.h"

#include <fmt/format.h>

#include <algorithm>
#include <mutex>
#include <stdexcept>

#include "mapping/movable_points.h"

namespace edgeslam {
namespace {

constexpr int kMaxNice = 19;

template <typename T>
void require(bool ok, const char* field, const char* rule, T value) {
  if (!ok) {
    throw std::invalid_argument(
        fmt::format("mapping back end: {} must be {} (got {})", field, rule, value));
  }
}

void checkMapper(const LocalMapperOptions& m) {
  require(m.triangulation_neighbours_mono >= 1, "mapper.triangulation_neighbours_mono",
          "at least 1", m.triangulation_neighbours_mono);
  require(m.triangulation_neighbours_depth >= 1, "mapper.triangulation_neighbours_depth",
          "at least 1", m.triangulation_neighbours_depth);
  require(m.fusion_neighbours_mono >= 1, "mapper.fusion_neighbours_mono", "at least 1",
          m.fusion_neighbours_mono);
  require(m.fusion_neighbours_depth >= 1, "mapper.fusion_neighbours_depth", "at least 1",
          m.fusion_neighbours_depth);
  require(m.triangulation_ratio > 0.f && m.triangulation_ratio <= 1.f, "mapper.triangulation_ratio",
          "in (0, 1]", m.triangulation_ratio);
  require(m.min_triangulation_parallax_deg > 0.0 && m.min_triangulation_parallax_deg < 90.0,
          "mapper.min_triangulation_parallax_deg", "in (0, 90)", m.min_triangulation_parallax_deg);
  require(m.direct_index_depth >= 0, "mapper.direct_index_depth", "at least 0",
          m.direct_index_depth);
  require(m.max_queue >= 1, "mapper.max_queue", "at least 1", m.max_queue);
  require(m.redundant_ratio > 0.0 && m.redundant_ratio <= 1.0, "mapper.redundant_ratio",
          "in (0, 1]", m.redundant_ratio);
  if (m.cull_revisits) {
    require(m.revisit_distance_ratio > 0.0, "mapper.revisit_distance_ratio", "positive",
            m.revisit_distance_ratio);
    require(m.revisit_max_angle_deg > 0.0 && m.revisit_max_angle_deg <= 180.0,
            "mapper.revisit_max_angle_deg", "in (0, 180]", m.revisit_max_angle_deg);
    require(m.revisit_min_shared_points >= 1, "mapper.revisit_min_shared_points", "at least 1",
            m.revisit_min_shared_points);
  }
}

void checkLoopCloser(const LoopCloserOptions& l) {
  if (l.global_ba) {
    require(l.global_ba_iterations >= 1, "loop_closer.global_ba_iterations", "at least 1",
            l.global_ba_iterations);
  }
  require(l.detector.consistency_required >= 1, "loop_closer.detector.consistency_required",
          "at least 1", l.detector.consistency_required);
  require(l.detector.direct_index_depth >= 0, "loop_closer.detector.direct_index_depth",
          "at least 0", l.detector.direct_index_depth);
  require(l.detector.min_shared_words_ratio > 0.0 && l.detector.min_shared_words_ratio <= 1.0,
          "loop_closer.detector.min_shared_words_ratio", "in (0, 1]",
          l.detector.min_shared_words_ratio);
  require(l.detector.min_group_score_ratio > 0.0 && l.detector.min_group_score_ratio <= 1.0,
          "loop_closer.detector.min_group_score_ratio", "in (0, 1]",
          l.detector.min_group_score_ratio);
  require(l.detector.group_neighbours >= 1, "loop_closer.detector.group_neighbours", "at least 1",
          l.detector.group_neighbours);
  require(l.verifier.min_bow_matches >= 1, "loop_closer.verifier.min_bow_matches", "at least 1",
          l.verifier.min_bow_matches);
  // A similarity needs three point pairs.
  require(l.verifier.min_sim3_inliers >= 3, "loop_closer.verifier.min_sim3_inliers", "at least 3",
          l.verifier.min_sim3_inliers);
  require(l.verifier.min_projected_matches >= 1, "loop_closer.verifier.min_projected_matches",
          "at least 1", l.verifier.min_projected_matches);
  require(l.verifier.guided_radius > 0.f, "loop_closer.verifier.guided_radius", "positive",
          l.verifier.guided_radius);
  require(l.verifier.projection_radius > 0.f, "loop_closer.verifier.projection_radius", "positive",
          l.verifier.projection_radius);
  require(l.correction.pose_graph_iterations >= 1, "loop_closer.correction.pose_graph_iterations",
          "at least 1", l.correction.pose_graph_iterations);
  require(l.correction.min_covisibility_weight >= 0,
          "loop_closer.correction.min_covisibility_weight", "at least 0",
          l.correction.min_covisibility_weight);
  require(l.correction.fuse_radius > 0.f, "loop_closer.correction.fuse_radius", "positive",
          l.correction.fuse_radius);
}

}  // namespace

void MappingBackendOptions::check() const {
  require(thread_nice >= 0 && thread_nice <= kMaxNice, "thread_nice", "within 0..19", thread_nice);
  require(thread_nice_when_segmenting >= 0 && thread_nice_when_segmenting <= kMaxNice,
          "thread_nice_when_segmenting", "within 0..19", thread_nice_when_segmenting);
  require(movable_point_erode_px >= 0, "movable_point_erode_px", "at least 0",
          movable_point_erode_px);
  checkMapper(mapper);
  // Without a vocabulary there is no loop closing, but its options are checked all the same: the
  // edge session that gets them may have one.
  if (loop_closing) {
    if (vocabulary != nullptr && vocabulary->empty()) {
      throw std::invalid_argument(
          "mapping back end: loop closing needs a trained vocabulary (this one is empty)");
    }
    checkLoopCloser(loop_closer);
  }
}

MappingBackend::MappingBackend(Map& map, const PinholeCamera& camera, Sensor sensor,
                               MappingBackendOptions options, MappingBackendHooks hooks)
    : map_(map),
      threaded_(options.threaded),
      movable_point_erode_px_(options.movable_point_erode_px),
      hooks_(std::move(hooks)) {
  options.check();
  const int nice = options.segmenter != nullptr
                       ? std::max(options.thread_nice, options.thread_nice_when_segmenting)
                       : options.thread_nice;
  LocalMapperOptions mapping = options.mapper;
  mapping.monocular = sensor == Sensor::kMonocular;
  mapping.thread_nice = nice;
  if (!mapping.vocabulary) mapping.vocabulary = options.vocabulary;
  mapper_ = std::make_unique<LocalMapper>(map_, camera, mapping);
  if (options.vocabulary != nullptr && options.loop_closing) {
    LoopCloserOptions loop = options.loop_closer;
    const LoopCloserOptions for_sensor = loopCloserOptionsFor(sensor);
    loop.verifier.fix_scale = for_sensor.verifier.fix_scale;
    loop.correction.fix_scale = for_sensor.correction.fix_scale;
    loop.threaded = threaded_;
    loop.thread_nice = nice;
    loop_closer_ =
        std::make_unique<LoopCloser>(map_, camera, options.vocabulary, loop, mapper_.get());
    if (hooks_.map_corrected) loop_closer_->setMapCorrectedCallback(hooks_.map_corrected);
    if (hooks_.parts_merged) loop_closer_->setPartsMergedCallback(hooks_.parts_merged);
  }
  if (hooks_.keyframe_mapped || loop_closer_) {
    mapper_->setKeyFrameMappedCallback([this](KeyFrame* keyframe) {
      if (hooks_.keyframe_mapped) hooks_.keyframe_mapped(keyframe);
      if (loop_closer_) loop_closer_->insertKeyFrame(keyframe);
    });
  }
  if (options.segmenter != nullptr) {
    segmentation_ = std::make_unique<KeyFrameSegmentationWorker>(
        options.segmenter,
        [this](KeyFrameSegmentationResult result) { onSegmented(std::move(result)); });
  }
}

MappingBackend::~MappingBackend() {
  stop();
}

void MappingBackend::adoptLoadedKeyFrames(const std::vector<KeyFrame*>& keyframes) {
  for (KeyFrame* keyframe : keyframes) {
    mapper_->describe(keyframe);
    if (loop_closer_) loop_closer_->fileKeyFrame(keyframe);
  }
}

void MappingBackend::start() {
  if (loop_closer_) loop_closer_->start();
  if (threaded_) mapper_->start();
}

void MappingBackend::stop() {
  if (segmentation_) segmentation_->stop();
  if (loop_closer_) loop_closer_->stop();
  mapper_->stop();
}

void MappingBackend::insertKeyFrame(KeyFrame* keyframe) {
  mapper_->insertKeyFrame(keyframe);
}

bool MappingBackend::acceptsKeyFrames() const {
  return mapper_->acceptsKeyFrames();
}

bool MappingBackend::acceptsUrgentKeyFrames() const {
  return mapper_->acceptsUrgentKeyFrames();
}

std::size_t MappingBackend::lastOptimizedFrame() const {
  return mapper_->lastOptimizedFrame();
}

void MappingBackend::onMapReset() {
  mapper_->onMapReset();
  if (loop_closer_) loop_closer_->onMapReset();
}

void MappingBackend::segment(KeyFrameSegmentationJob job) {
  if (!segmentation_) throw std::logic_error("MappingBackend::segment without a segmenter");
  segmentation_->submit(std::move(job));
  if (!threaded_) segmentation_->waitUntilIdle();
}

void MappingBackend::setNmsThreshold(float nm) {
  if (segmentation_) segmentation_->setNmsThreshold(nm);
}

void MappingBackend::onSegmented(KeyFrameSegmentationResult result) {
  std::size_t erased = 0;
  {
    MutexLock lock(map_.updateMutex());
    if (KeyFrame* keyframe = map_.keyFrame(result.keyframe)) {
      erased = eraseMovablePoints(map_, *keyframe, result.labels, movable_point_erode_px_);
    }
  }
  // A frame segmented before the map existed (kInvalidId) serves tracking only.
  if (result.keyframe != kInvalidId) ++keyframes_segmented_;
  movable_points_erased_ += erased;
  if (hooks_.keyframe_segmented) hooks_.keyframe_segmented(std::move(result));
}

void MappingBackend::processAll() {
  if (threaded_) return;
  mapper_->processAll();
  if (loop_closer_) loop_closer_->processAll();
}

void MappingBackend::waitUntilKeyFramesMapped() {
  mapper_->waitUntilIdle();
  if (segmentation_) segmentation_->waitUntilIdle();
}

void MappingBackend::waitUntilSegmented() {
  if (segmentation_) segmentation_->waitUntilIdle();
}

void MappingBackend::waitUntilIdle() {
  if (segmentation_) segmentation_->waitUntilIdle();
  mapper_->waitUntilIdle();
  if (loop_closer_) loop_closer_->waitUntilIdle();
}

std::optional<std::string> MappingBackend::failure() const {
  if (auto cause = mapper_->failure()) return cause;
  if (loop_closer_) {
    if (auto cause = loop_closer_->failure()) return cause;
  }
  if (segmentation_) return segmentation_->failure();
  return std::nullopt;
}

MappingBackendCounters MappingBackend::counters() const {
  MappingBackendCounters out;
  out.loops = loops();
  if (loop_closer_) {
    for (const LoopEvent& event : loop_closer_->stats().events) {
      if (event.keyframes_merged > 0) ++out.merges;
    }
  }
  out.keyframes_segmented = keyframes_segmented_.load();
  out.movable_points_erased = movable_points_erased_.load();
  if (segmentation_) {
    const KeyFrameSegmentationCounters segmentation = segmentation_->counters();
    out.segmentation_ms = segmentation.segmentation_ms;
    out.keyframes_not_segmented = segmentation.skipped;
  }
  return out;
}

}  // namespace edgeslam
