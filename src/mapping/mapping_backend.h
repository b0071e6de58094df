#pragma once
// The mapping back end: what keeps a global map once tracking has made its keyframes. Local
// mapping, loop closing (with a vocabulary) and, with a segmenter, keyframe segmentation with the
// removal of the points on movable objects, on threads of their own or inline after each frame.
// Local mode (LocalSlam) and every edge session (EdgeMapSession) compose this one class: they
// differ only in where keyframes come from and what the hooks do with the results.
//
// Threading: insertKeyFrame, segment and the queries may be called from any thread; start, stop,
// processAll and adoptLoadedKeyFrames from the owner's. Hooks run on the worker that made the
// change (the caller's, unthreaded), without the map's update mutex held.
#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "map/keyframe_sink.h"
#include "map/map.h"
#include "map/sensor.h"
#include "mapping/keyframe_segmentation.h"
#include "mapping/local_mapper.h"
#include "mapping/loop_closer.h"
#include "place/vocabulary.h"
#include "semantic/segmenter.h"
#include "util/timing_stats.h"

namespace edgeslam {

struct MappingBackendOptions {
  // The back end sets mapper.monocular (from the sensor), mapper.thread_nice and, when unset,
  // mapper.vocabulary (to `vocabulary`).
  LocalMapperOptions mapper;
  // Place recognition for loop closing, and the mapper's bag-of-words triangulation search.
  std::shared_ptr<const Vocabulary> vocabulary;
  bool loop_closing = true;  // with a vocabulary
  // Scale fixing follows the sensor, threading and nice the fields below; the rest is used as is.
  LoopCloserOptions loop_closer;
  // false: nothing runs on a thread of its own but segmentation, which is waited for; processAll()
  // maps and closes loops on the caller's thread (deterministic runs and tests).
  bool threaded = true;
  // Nice increment of the mapping and loop-closing threads (util/thread_priority.h), so that on a
  // shared core tracking or segmentation goes first.
  int thread_nice = 0;
  // Keyframes are segmented by this segmenter on a thread of its own, and the points on movable
  // objects erased from the map; nullptr = no segmentation.
  std::shared_ptr<Segmenter> segmenter;
  // With a segmenter, mapping and loop closing run at least this nice.
  int thread_nice_when_segmenting = 0;
  int movable_point_erode_px = 2;  // mask erosion before points are erased (movable_points.h)

  // Throws std::invalid_argument, one line naming the field, for a value the back end cannot
  // work with. MappingBackend's constructor calls it.
  void check() const;
};

// What the owner is told; each may be empty.
struct MappingBackendHooks {
  // After each keyframe is mapped, before loop closing takes it.
  std::function<void(KeyFrame*)> keyframe_mapped;
  // After each loop correction and each applied global bundle adjustment.
  std::function<void()> map_corrected;
  // When a loop merges two parts of the map: the move one part made, told under the map's update
  // mutex (the hook must not take it), before the rest of the correction and map_corrected.
  std::function<void(const MapPartMerge&)> parts_merged;
  // After a keyframe's segmentation, once its movable points are erased (the keyframe may have
  // been culled meanwhile: the labels are still worth having).
  std::function<void(KeyFrameSegmentationResult)> keyframe_segmented;
};

struct MappingBackendCounters {
  std::uint64_t loops = 0;
  std::uint64_t merges = 0;  // of those, loops that joined two parts of the map
  std::uint64_t keyframes_segmented = 0;
  std::uint64_t keyframes_not_segmented = 0;  // left the segmentation queue beyond its bound
  std::uint64_t movable_points_erased = 0;
  PercentileSummary segmentation_ms;
};

class MappingBackend : public KeyFrameSink {
 public:
  // `map` and `camera` outlive the back end. No thread maps before start().
  MappingBackend(Map& map, const PinholeCamera& camera, Sensor sensor,
                 MappingBackendOptions options, MappingBackendHooks hooks = {});
  ~MappingBackend() override;
  MappingBackend(const MappingBackend&) = delete;
  MappingBackend& operator=(const MappingBackend&) = delete;

  // Keyframes already in the map (a stored map resumed): described (bags of words) and filed for
  // place recognition, without mapping them again. Before start().
  void adoptLoadedKeyFrames(const std::vector<KeyFrame*>& keyframes);
  // Starts loop closing and, threaded, local mapping.
  void start();
  // Stops segmentation, loop closing, then mapping (in that order: each may still feed the next).
  void stop();

  // KeyFrameSink: keyframes go to local mapping; a map reset reaches mapping and loop closing.
  void insertKeyFrame(KeyFrame* keyframe) override;
  bool acceptsKeyFrames() const override;
  bool acceptsUrgentKeyFrames() const override;
  std::size_t lastOptimizedFrame() const override;
  void onMapReset() override;

  // Queues a keyframe's image for segmentation (waits for it, unthreaded); job.keyframe kInvalidId:
  // a frame before the map exists (its mask serves tracking only). Needs a segmenter.
  void segment(KeyFrameSegmentationJob job);
  bool segments() const { return segmentation_ != nullptr; }
  // Box NMS threshold of the segmenter (paper Table I's nm), from the next keyframe on.
  void setNmsThreshold(float nm);

  // Unthreaded: maps every queued keyframe, then closes loops, on the caller's thread. Threaded:
  // nothing (the threads do it).
  void processAll();
  // Until segmentation and local mapping have done every keyframe given to them (tracking's pace
  // when frames are fed back to back).
  void waitUntilKeyFramesMapped();
  // Until segmentation, mapping and loop closing (its global BA too) are all idle.
  void waitUntilIdle();
  // Until every keyframe given to segmentation is segmented (its mask handed on).
  void waitUntilSegmented();

  // Why one of the workers (mapping, loop closing, segmentation) ended with an exception: the
  // back end is then over. nullopt while they run.
  std::optional<std::string> failure() const;
  MappingBackendCounters counters() const;
  std::size_t loops() const { return loop_closer_ ? loop_closer_->loops() : 0; }
  const LocalMapper& mapper() const { return *mapper_; }
  // nullptr without a vocabulary or with loop closing off.
  const LoopCloser* loopCloser() const { return loop_closer_.get(); }
  // nullptr without a segmenter.
  const KeyFrameSegmentationWorker* segmentation() const { return segmentation_.get(); }

 private:
  void onSegmented(KeyFrameSegmentationResult result);

  Map& map_;
  bool threaded_;
  int movable_point_erode_px_;
  MappingBackendHooks hooks_;
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<LoopCloser> loop_closer_;
  std::unique_ptr<KeyFrameSegmentationWorker> segmentation_;
  std::atomic<std::uint64_t> keyframes_segmented_{0};
  std::atomic<std::uint64_t> movable_points_erased_{0};
};

}  // namespace edgeslam
