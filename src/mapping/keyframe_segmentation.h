#pragma once
// Segmentation of keyframes on a worker thread of its own, so that mapping never waits for the
// network's inference (paper Sec. IV-B: only keyframes are segmented). The newest keyframe is
// segmented first (its mask serves tracking best); the older ones wait for a quiet moment rather
// than being skipped, since a keyframe never segmented keeps the points it made on people in the
// map for good (the first keyframes of an RGB-D run come one per frame, before any mask: 5-7 of 10
// were skipped, and the ATE at --realtime was 1.3-1.9x the static run's). Beyond the bound the
// oldest waiting keyframe is skipped.
#include <atomic>
#include <cstddef>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>

#include "map/ids.h"
#include "semantic/segmenter.h"
#include "util/mutex.h"
#include "util/queued_worker.h"
#include "util/timing_stats.h"

namespace edgeslam {

struct KeyFrameSegmentationJob {
  KeyFrameId keyframe = kInvalidId;
  std::size_t frame_index = 0;
  cv::Mat image;       // BGR or grey, possibly reduced
  cv::Size full_size;  // the camera's image size: the labels come back at this size
  int reduce = 1;      // the worker shrinks the image this many times before segmenting it
};

struct KeyFrameSegmentationResult {
  KeyFrameId keyframe = kInvalidId;
  std::size_t frame_index = 0;
  cv::Mat1b labels;  // full_size, 0 = background, i + 1 = instance i
  std::size_t instances = 0;
  double segmentation_ms = 0.0;
};

struct KeyFrameSegmentationCounters {
  std::size_t segmented = 0;
  std::size_t skipped = 0;  // left the queue unsegmented
  std::size_t failed = 0;
  PercentileSummary segmentation_ms;
};

class KeyFrameSegmentationWorker {
 public:
  using Done = std::function<void(KeyFrameSegmentationResult)>;

  // `done` runs on the worker thread. The segmenter is used by that thread only.
  KeyFrameSegmentationWorker(std::shared_ptr<Segmenter> segmenter, Done done,
                             std::size_t max_queued = 16);
  ~KeyFrameSegmentationWorker();
  KeyFrameSegmentationWorker(const KeyFrameSegmentationWorker&) = delete;
  KeyFrameSegmentationWorker& operator=(const KeyFrameSegmentationWorker&) = delete;

  void submit(KeyFrameSegmentationJob job);
  // Box NMS threshold nm (paper Table I), applied from the next keyframe on.
  void setNmsThreshold(float nm);
  // Until the queue is empty and no keyframe is being segmented.
  void waitUntilIdle();
  void stop();
  KeyFrameSegmentationCounters counters() const;
  // Why the worker thread ended with an exception (a failed segmentation of one keyframe is
  // counted, not this); nullopt if it did not.
  std::optional<std::string> failure() const { return queue_.failure(); }

 private:
  // The queue's work: one keyframe segmented, its labels handed to `done`, counted.
  void segment(KeyFrameSegmentationJob job);

  std::shared_ptr<Segmenter> segmenter_;
  Done done_;
  std::atomic<float> pending_nms_{-1.f};
  mutable Mutex counters_mutex_;
  std::size_t segmented_ GUARDED_BY(counters_mutex_) = 0;
  std::size_t failed_ GUARDED_BY(counters_mutex_) = 0;
  SampleStats segmentation_ms_ GUARDED_BY(counters_mutex_);
  // Last: its thread, which uses everything above, ends before any of it is destroyed. The jobs
  // it drops when full are the skipped ones.
  QueuedWorker<KeyFrameSegmentationJob> queue_;
};

}  // namespace edgeslam
