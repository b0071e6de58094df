#pragma once
// Loop closing on its own thread: takes each keyframe once local mapping is done with it, looks for
// a place seen before (loop_detector.h), verifies it geometrically (loop_verifier.h), closes the
// loop with mapping paused (loop_correction.h), then refines the whole map by a global bundle
// adjustment on another thread that tracking and mapping do not wait for; a newer loop abandons it
// (loop_global_ba.h). Every map change goes through Map under its update mutex.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_participant.h"
#include "map/sensor.h"
#include "mapping/local_mapper.h"
#include "mapping/loop_correction.h"
#include "mapping/loop_detector.h"
#include "mapping/loop_verifier.h"
#include "place/vocabulary.h"
#include "util/mutex.h"
#include "util/queued_worker.h"
#include "util/timing_stats.h"
#include "util/worker_thread.h"

namespace edgeslam {

struct LoopCloserOptions {
  // false: nothing runs on a thread of its own; processAll() detects, corrects and runs the global
  // bundle adjustment on the caller's thread (deterministic tests).
  bool threaded = true;
  bool global_ba = true;
  int global_ba_iterations = 10;
  // The global BA adjusts the part of the map the loop is in; a part larger than this is left to
  // the essential graph's correction (bench/map_scale_bench.py: on a 3000-keyframe map one
  // iteration took seconds and the next loop waited ~10 s for the BA to notice its cancellation).
  std::size_t global_ba_max_keyframes = 2000;
  // Nice increment for the loop-closing and global-BA threads (util/thread_priority.h).
  int thread_nice = 0;
  // No search while the map is this small, nor within this many keyframes of the last loop.
  std::size_t min_map_keyframes = 10;
  std::size_t min_keyframes_since_loop = 10;
  LoopDetectorOptions detector;
  LoopVerifierOptions verifier;
  LoopCorrectionOptions correction;
};

// The options for a sensor: scale is free for monocular maps and fixed otherwise.
LoopCloserOptions loopCloserOptionsFor(Sensor sensor);

struct LoopEvent {
  KeyFrameId current = kInvalidId;
  KeyFrameId loop = kInvalidId;
  std::size_t current_frame = 0;
  std::size_t loop_frame = 0;
  int sim3_inliers = 0;
  int matched_points = 0;
  double scale = 1.0;
  double translation_m = 0.0;  // how far the correction moved the current keyframe
  double rotation_deg = 0.0;
  double correction_ms = 0.0;  // verification excluded: correction and essential graph
  double pose_graph_ms = 0.0;
  // A loop that joined two parts of the map (two clients', or a session begun on a map of its
  // own): the keyframes moved onto the other part first. 0 for an ordinary loop.
  std::size_t keyframes_merged = 0;
};

struct LoopCloserStats {
  std::size_t keyframes_processed = 0;
  std::size_t keyframes_with_candidates = 0;  // consistent candidates reached verification
  std::size_t loops = 0;
  std::size_t global_ba_started = 0;
  std::size_t global_ba_applied = 0;
  std::size_t global_ba_cancelled = 0;
  std::size_t global_ba_too_large = 0;  // the loop's part above global_ba_max_keyframes
  std::vector<LoopEvent> events;
  std::vector<double> global_ba_ms;  // solve and write-back of each applied run
  // After a loop's correction, the wait for the global BA it cancelled to stop (on the loop
  // thread, before the next BA starts; the correction itself does not wait).
  SampleStats global_ba_handover_ms;
  // Per keyframe: describing it, querying the place database and verifying the candidates.
  SampleStats detection_ms;
};

class LoopCloser {
 public:
  // `mapper` (may be null) is paused while a loop is corrected or a global BA written back.
  // Throws std::invalid_argument without a usable vocabulary.
  LoopCloser(Map& map, const PinholeCamera& camera, std::shared_ptr<const Vocabulary> vocabulary,
             LoopCloserOptions options, LocalMapper* mapper);
  ~LoopCloser();
  LoopCloser(const LoopCloser&) = delete;
  LoopCloser& operator=(const LoopCloser&) = delete;

  // Starts the thread when options.threaded (a no-op otherwise).
  void start();
  void stop();
  // Queues a mapped keyframe (any thread).
  void insertKeyFrame(KeyFrame* keyframe);
  // Files a keyframe of a loaded map for place recognition, without searching a loop for it.
  // Before start() (or unthreaded, between keyframes).
  void fileKeyFrame(KeyFrame* keyframe);
  // Unthreaded: processes the queue now. Threaded: same as waitUntilIdle().
  void processAll();
  // Returns when the queue is empty and no global BA runs.
  void waitUntilIdle();
  // Forget every keyframe (the map was cleared); takes effect before the next keyframe.
  void onMapReset();

  // Called after each loop correction and each applied global BA, without the map mutex held,
  // from whichever thread made the change (set before start()).
  void setMapCorrectedCallback(std::function<void()> callback) {
    on_corrected_ = std::move(callback);
  }
  // Called when a loop merges two parts of the map, with the move one part made, at once: under
  // the map's update mutex, which it must not take (set before start()).
  void setPartsMergedCallback(std::function<void(const MapPartMerge&)> callback) {
    on_merged_ = std::move(callback);
  }

  std::size_t loops() const { return loops_.load(); }
  LoopCloserStats stats() const;
  // The loops closed from the `first`-th on (stats().events without copying the rest).
  std::vector<LoopEvent> eventsFrom(std::size_t first) const;
  // Why the loop-closing thread (or a global BA thread) ended with an exception; nullopt if not.
  std::optional<std::string> failure() const;

 private:
  // The queue's work: one keyframe, then erased keyframes released.
  void closeLoopsAt(KeyFrame* keyframe);
  void processKeyFrame(KeyFrame* keyframe);
  void closeLoop(const VerifiedLoop& loop);
  // Over the part of the map `loop_keyframe` is in.
  void launchGlobalBundleAdjustment(KeyFrameId loop_keyframe);
  void globalBundleAdjustment(KeyFrameId loop_keyframe);
  void stopGlobalBundleAdjustment();
  // Between keyframes: lets go of erased keyframes so that the map can free them.
  void releaseErased();

  Map& map_;
  const PinholeCamera& camera_;
  LoopCloserOptions options_;
  MapParticipant map_participant_;
  LocalMapper* mapper_;
  LoopDetector detector_;
  std::size_t keyframes_since_loop_ = 0;

  std::atomic<bool> reset_requested_{false};

  mutable Mutex
      global_ba_mutex_;  // guards global_ba_thread_ (launched and joined from two threads)
  WorkerThread global_ba_thread_ GUARDED_BY(global_ba_mutex_);
  std::atomic<bool> cancel_global_ba_{false};

  std::atomic<std::size_t> loops_{0};
  mutable Mutex stats_mutex_;
  LoopCloserStats stats_ GUARDED_BY(stats_mutex_);
  std::function<void()> on_corrected_;
  std::function<void(const MapPartMerge&)> on_merged_;
  // Last: its thread, which uses everything above, ends before any of it is destroyed.
  QueuedWorker<KeyFrame*> queue_;
};

}  // namespace edgeslam
