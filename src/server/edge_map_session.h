#pragma once
// One client's session on the edge: the global map, fed by the client's keyframe uploads and kept
// by local mapping on its own thread and, with a vocabulary, by loop closing on another; after each
// mapped keyframe, loop correction and global bundle adjustment, what changed goes back to the
// client as a map slice.
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <unordered_map>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_change_observer.h"
#include "map/map_records.h"
#include "map/sensor.h"
#include "mapping/mapping_backend.h"
#include "server/client_map_window.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

// An edge session's back end by default: as local mode's, but with a segmenter, mapping and loop
// closing run at least nice 10. On the edge's one core a late mask costs the client more than a
// late map point: 7-Scenes seed 11, 5 edge runs each, segmentation 137-156 ms instead of 201-252
// and the transferred-mask IoU 0.42-0.61 instead of 0.00-0.48, ATE no worse.
MappingBackendOptions edgeSessionBackendOptions();

struct EdgeMapSessionOptions {
  // Mapping, loop closing and, with backend.segmenter, segmentation of keyframes uploaded with an
  // image (one segmenter per session). backend.threaded = false maps each keyframe inside
  // onKeyFrame (deterministic tests).
  MappingBackendOptions backend = edgeSessionBackendOptions();
  int mask_downscale = 4;  // the label image travels at 1/this of the camera's resolution
  // The client's bounded map (window.keyframes = 0: it replicates the whole global map).
  ClientMapWindowOptions window;
  // Fills the empty global map before the session's threads start (a stored map resumed after a
  // server restart); its keyframes are then described (bags of words), filed for place
  // recognition and taken as held by the client.
  std::function<void(Map&)> preload;
};

struct EdgeMapSessionStats {
  std::uint64_t uploads = 0;
  std::uint64_t slices = 0;
  std::uint64_t keyframes = 0;
  std::uint64_t map_points = 0;
  std::uint64_t keyframes_segmented = 0;
  std::uint64_t movable_points_erased = 0;
  std::uint64_t client_keyframes_held = 0;  // bounded client map: as the edge counts them
  std::uint64_t client_keyframes_evicted = 0;
  std::uint64_t client_keyframes_resent = 0;  // sent back into the window
  // Uploaded keypoints whose descriptor the wire left out: filled from their map point, or lost
  // (the point was gone: the keypoint keeps neither point nor descriptor).
  std::uint64_t descriptors_filled = 0;
  std::uint64_t descriptors_lost = 0;
  // Uploads of a keyframe the map already had (a client re-sending after a full resync): answered
  // by a slice, not mapped again.
  std::uint64_t uploads_duplicate = 0;
  std::uint64_t full_resyncs = 0;      // slices with full_resync published
  std::uint64_t keyframes_loaded = 0;  // by options.preload
  double load_describe_ms = 0.0;       // bags of words of those
};

class EdgeMapSession {
 public:
  using Publish = std::function<void(MapSlice)>;

  EdgeMapSession(const PinholeCamera& camera, Sensor sensor, EdgeMapSessionOptions options,
                 Publish publish);
  ~EdgeMapSession();
  EdgeMapSession(const EdgeMapSession&) = delete;
  EdgeMapSession& operator=(const EdgeMapSession&) = delete;

  // Adds the keyframe and its new points to the global map and queues it for mapping. Descriptors
  // the upload left out (features.descriptor_omitted) are those of the points their keypoints
  // name (fillOmittedDescriptors). Throws std::invalid_argument for records that contradict
  // themselves.
  void onKeyFrame(const KeyFrameUpload& upload);
  // Publishes a slice with full_resync set: the pose of every keyframe the edge map holds (the
  // list a client compares with its own to re-send what the edge lacks) and every point. The
  // changes pending are taken by it (and told to the observer) as an ordinary slice takes them.
  void publishFullResync();
  // Waits until every queued keyframe is mapped and its slice published.
  void finish();
  void stop();

  EdgeMapSessionStats stats() const;
  // Why one of the session's workers (mapping, loop closing, segmentation) ended with an
  // exception: the session is over. nullopt while they run.
  std::optional<std::string> failure() const;
  Map& map() { return map_; }
  // The keyframes the client holds (lock the map's update mutex while reading).
  const ClientMapWindow& clientWindow() const { return window_; }
  // nullptr without a vocabulary or with loop closing off.
  const LoopCloser* loopCloser() const { return backend_->loopCloser(); }
  // nullptr without segmentation.
  const KeyFrameSegmentationWorker* segmentation() const { return backend_->segmentation(); }
  // Box NMS threshold of the segmenter (paper Table I's nm), from the next keyframe on.
  void setNmsThreshold(float nm);
  // Told every change of the global map (uploads applied too) and every mask; set before the
  // first keyframe. Not owned: it outlives the session's threads (stop() first).
  void setChangeObserver(MapChangeObserver* observer) { observer_ = observer; }

 private:
  // `mapped`: the keyframe just mapped, or nullptr for a loop correction or global BA.
  // `answers`: an upload the slice answers although nothing was mapped for it (a duplicate).
  void publishSlice(KeyFrame* mapped, std::uint64_t answers = 0);
  void adoptPreloadedMap();
  void onSegmented(KeyFrameSegmentationResult result);

  PinholeCamera camera_;
  Map map_;
  MapChangeObserver* observer_ = nullptr;
  int mask_downscale_;
  Publish publish_;
  ClientMapWindow window_ GUARDED_BY(map_.updateMutex());
  KeyFrameId window_centre_ GUARDED_BY(map_.updateMutex()) = kInvalidId;  // the last mapped

  // Mapping and loop closing publish from their own threads: slices leave in sequence order.
  Mutex publish_mutex_;
  std::size_t loops_published_ GUARDED_BY(publish_mutex_) = 0;
  mutable Mutex state_mutex_;  // guards the fields below (not the map)
  std::uint64_t slice_sequence_ GUARDED_BY(state_mutex_) = 0;
  std::unordered_map<KeyFrameId, std::uint64_t> upload_of_keyframe_ GUARDED_BY(state_mutex_);
  KeyFrameId newest_keyframe_ GUARDED_BY(state_mutex_) = kInvalidId;
  EdgeMapSessionStats stats_ GUARDED_BY(state_mutex_);
  std::vector<MaskRecord> pending_masks_ GUARDED_BY(state_mutex_);

  // Last: its threads stop (in stop()) before the state above goes.
  std::unique_ptr<MappingBackend> backend_;
};

}  // namespace edgeslam
