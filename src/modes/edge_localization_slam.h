#pragma once
// `--localize-only` in edge mode (`run --mode edge` and `client`): the client localises in a map
// the edge holds in its store and changes nothing in it. The edge relocalises the client's lost
// frames against the whole map and sends the part of it around the place found (the client's map
// window); the client tracks against that part, and as it moves the edge moves the window with
// it. No keyframe is made; poses are in the stored map's frame.
#include <atomic>
#include <chrono>
#include <memory>

#include "modes/edge_link.h"
#include "modes/slam_system.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

class EdgeLocalizationSlam : public TrackingSlam {
 public:
  // `link` has opened a localise-only session (SessionSettings::localize_only) on a stored map.
  EdgeLocalizationSlam(const PinholeCamera& camera, SlamOptions options,
                       std::unique_ptr<EdgeLink> link);
  ~EdgeLocalizationSlam() override;

  // Waits (bounded) for the answer to the question in flight.
  void finish() override;
  SlamCounters counters() const override;
  LinkTraffic linkTraffic() const override;
  const char* modeName() const override { return "edge"; }
  // The stored map's size as the edge says it (the client holds a window of it).
  std::size_t keyFrameCount() const override;
  std::size_t mapPointCount() const override;

  double max_answer_wait_s = 10.0;  // --fast: a question unanswered this long is given up on

 private:
  void onSlice(MapSlice slice);
  void beforeTracking(std::size_t frame_index, const cv::Mat& image) override;
  void afterTracking(const TrackResult& result, std::size_t frame_index,
                     const cv::Mat& image) override;
  // A lost frame: its features, for the edge to relocalise. A tracked one: the stored keyframe it
  // tracks against, for the edge to move the window to.
  void ask(std::size_t frame_index, const TrackResult& result);
  bool answerPending() const;
  void waitForAnswer();

  std::unique_ptr<EdgeLink> link_;
  std::uint64_t sequence_ = 0;             // of the last question (tracking thread)
  KeyFrameId window_centre_ = kInvalidId;  // the keyframe the window was last moved to
  using Clock = std::chrono::steady_clock;
  mutable Mutex mutex_;  // the link's thread (slices) against the tracking thread
  std::uint64_t answered_ GUARDED_BY(mutex_) = 0;  // sequence of the last question answered
  Clock::time_point asked_at_ GUARDED_BY(mutex_);
  KeyFrameId relocalized_near_ GUARDED_BY(mutex_) = kInvalidId;  // for the tracker, once
  std::uint64_t map_keyframes_ GUARDED_BY(mutex_) = 0;
  std::uint64_t map_points_ GUARDED_BY(mutex_) = 0;
  std::uint64_t slices_applied_ GUARDED_BY(mutex_) = 0;
  EdgeLocalizationCounters localization_ GUARDED_BY(mutex_);
  SampleStats answer_ms_ GUARDED_BY(mutex_);
};

}  // namespace edgeslam
