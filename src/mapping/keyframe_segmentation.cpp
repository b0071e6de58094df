#include "mapping/keyframe_segmentation.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace edgeslam {

KeyFrameSegmentationWorker::KeyFrameSegmentationWorker(std::shared_ptr<Segmenter> segmenter,
                                                       Done done, std::size_t max_queued)
    : segmenter_(std::move(segmenter)),
      done_(std::move(done)),
      queue_("keyframe segmentation",
             [this](KeyFrameSegmentationJob job) { segment(std::move(job)); },
             {.capacity = std::max<std::size_t>(1, max_queued),
              .newest_first = true,
              .thread_nice = 0,
              .on_failure = {},
              .group = {},
              .backlog = 0}) {
  queue_.start();
}

KeyFrameSegmentationWorker::~KeyFrameSegmentationWorker() {
  stop();
}

void KeyFrameSegmentationWorker::submit(KeyFrameSegmentationJob job) {
  queue_.push(std::move(job));
}

void KeyFrameSegmentationWorker::setNmsThreshold(float nm) {
  pending_nms_ = nm;
}

void KeyFrameSegmentationWorker::waitUntilIdle() {
  queue_.waitUntilIdle();
}

void KeyFrameSegmentationWorker::stop() {
  queue_.stop();
}

KeyFrameSegmentationCounters KeyFrameSegmentationWorker::counters() const {
  const std::size_t skipped = queue_.dropped();
  MutexLock lock(counters_mutex_);
  return {segmented_, skipped, failed_, segmentation_ms_.summary()};
}

void KeyFrameSegmentationWorker::segment(KeyFrameSegmentationJob job) {
  const float nms = pending_nms_.exchange(-1.f);
  KeyFrameSegmentationResult result;
  result.keyframe = job.keyframe;
  result.frame_index = job.frame_index;
  bool ok = true;
  try {
    if (nms >= 0.f) segmenter_->setNmsThreshold(nms);
    Stopwatch timer;
    cv::Mat image = job.image;
    if (job.reduce > 1) {
      cv::resize(job.image, image,
                 cv::Size((job.image.cols + job.reduce - 1) / job.reduce,
                          (job.image.rows + job.reduce - 1) / job.reduce),
                 0, 0, cv::INTER_AREA);
    }
    const Segmentation segmentation = segmenter_->segment(image);
    if (segmentation.label_image.size() == job.full_size) {
      result.labels = segmentation.label_image;
    } else {
      cv::resize(segmentation.label_image, result.labels, job.full_size, 0, 0, cv::INTER_NEAREST);
    }
    result.instances = segmentation.instances.size();
    result.segmentation_ms = timer.elapsedMs();
  } catch (const std::exception& e) {
    spdlog::error("segmentation of keyframe at frame {} failed: {}", job.frame_index, e.what());
    ok = false;
  }
  const double elapsed_ms = result.segmentation_ms;
  if (ok) done_(std::move(result));
  MutexLock lock(counters_mutex_);
  if (ok) {
    ++segmented_;
    segmentation_ms_.add(elapsed_ms);
  } else {
    ++failed_;
  }
}

}  // namespace edgeslam
