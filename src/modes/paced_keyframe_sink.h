#pragma once
// Offline pacing (`--fast`): a keyframe sink that holds tracking back until the back end (the local
// mapper, the edge) has finished the previous keyframe, so that frames fed back to back build the
// map a camera-paced run builds. Without it the back end fell behind: its local BA was cut short
// by every new keyframe and tracking was refused keyframes, and the map's scale drifted (KITTI 03,
// 400 frames, monocular: ATE 2.92 m fed back to back against 0.71 m at the camera's pace).
//
// The wait happens when the next keyframe is handed over, outside the map's update mutex, so
// tracking of the frames in between still overlaps the back end's work on the last keyframe: at
// most one keyframe is in flight. The sink also counts the frames at which the back end refused
// keyframes (its backlog), for the run's warnings.
#include <atomic>
#include <cstdint>
#include <functional>

#include "map/keyframe_sink.h"
#include "util/mutex.h"
#include "util/timing_stats.h"

namespace edgeslam {

struct BackendPacing {
  std::uint64_t waits = 0;          // keyframes that waited for the back end
  double wait_total_ms = 0.0;       // tracking's time spent waiting, all keyframes
  PercentileSummary wait_ms;        // per wait
  std::uint64_t busy_refusals = 0;  // decisions at which the back end could take no keyframe
};

// Tracking's waits for its back end, counted the same wherever tracking runs (here, and for
// offload mode on the client from the waits the edge reports). Not synchronised.
class BackendWaits {
 public:
  // A wait this short found the back end idle already (a lock taken and released): not counted.
  static constexpr double kWaitedMs = 0.1;

  void add(double ms) {
    if (ms < kWaitedMs) return;
    waits_ms_.add(ms);
    total_ms_ += ms;
  }
  double totalMs() const { return total_ms_; }
  BackendPacing pacing(std::uint64_t busy_refusals = 0) const {
    return {waits_ms_.count(), total_ms_, waits_ms_.summary(), busy_refusals};
  }

 private:
  SampleStats waits_ms_;
  double total_ms_ = 0.0;
};

class PacedKeyFrameSink : public KeyFrameSink {
 public:
  // `wait_until_idle` blocks until the back end has done everything it was given; null: no
  // waiting (camera-paced runs), only the counting.
  PacedKeyFrameSink(KeyFrameSink& inner, std::function<void()> wait_until_idle);

  void insertKeyFrame(KeyFrame* keyframe) override;
  bool acceptsKeyFrames() const override;
  bool acceptsUrgentKeyFrames() const override { return inner_.acceptsUrgentKeyFrames(); }
  std::size_t lastOptimizedFrame() const override { return inner_.lastOptimizedFrame(); }
  bool mapUpdatesPaused() const override { return inner_.mapUpdatesPaused(); }
  void onMapReset() override { inner_.onMapReset(); }

  BackendPacing pacing() const;
  double waitTotalMs() const;
  // Another wait of tracking for the back end (counted with the keyframes' own).
  void waitFor(const std::function<void()>& wait);

 private:
  KeyFrameSink& inner_;
  std::function<void()> wait_until_idle_;
  mutable Mutex mutex_;
  BackendWaits waits_ GUARDED_BY(mutex_);
  mutable std::atomic<std::uint64_t> busy_refusals_{0};
};

}  // namespace edgeslam
