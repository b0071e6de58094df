#include "mapping/keyframe_segmentation.h"

#include <spdlog/spdlog.h>

#include <opencv2/imgproc.hpp>

namespace edgeslam {

KeyFrameSegmentationWorker::KeyFrameSegmentationWorker(std::shared_ptr<Segmenter> segmenter,
                                                       Done done, std::size_t max_queued)
    : segmenter_(std::move(segmenter)),
      done_(std::move(done)),
      max_queued_(std::max<std::size_t>(1, max_queued)) {
  thread_.start(
      "keyframe segmentation", [this] { run(); },
      [this](const std::string&) {
        MutexLock lock(mutex_);
        stopping_ = true;
        busy_ = false;
        idle_.notify_all();
      });
}

KeyFrameSegmentationWorker::~KeyFrameSegmentationWorker() {
  stop();
}

void KeyFrameSegmentationWorker::submit(KeyFrameSegmentationJob job) {
  MutexLock lock(mutex_);
  if (stopping_) return;
  queue_.push_back(std::move(job));
  while (queue_.size() > max_queued_) {
    queue_.pop_front();
    ++skipped_;
  }
  wake_.notify_all();
}

void KeyFrameSegmentationWorker::setNmsThreshold(float nm) {
  MutexLock lock(mutex_);
  pending_nms_ = nm;
}

void KeyFrameSegmentationWorker::waitUntilIdle() {
  MutexLock lock(mutex_);
  lock.wait(idle_, [&]() REQUIRES(mutex_) { return stopping_ || (queue_.empty() && !busy_); });
}

void KeyFrameSegmentationWorker::stop() {
  {
    MutexLock lock(mutex_);
    stopping_ = true;
    wake_.notify_all();
    idle_.notify_all();
  }
  thread_.join();
}

KeyFrameSegmentationCounters KeyFrameSegmentationWorker::counters() const {
  MutexLock lock(mutex_);
  return {segmented_, skipped_, failed_, segmentation_ms_.summary()};
}

void KeyFrameSegmentationWorker::run() {
  while (true) {
    KeyFrameSegmentationJob job;
    float nms = -1.f;
    {
      MutexLock lock(mutex_);
      lock.wait(wake_, [&]() REQUIRES(mutex_) { return stopping_ || !queue_.empty(); });
      if (stopping_) return;
      job = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
      std::swap(nms, pending_nms_);
    }
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
    MutexLock lock(mutex_);
    busy_ = false;
    if (ok) {
      ++segmented_;
      segmentation_ms_.add(elapsed_ms);
    } else {
      ++failed_;
    }
    if (queue_.empty()) idle_.notify_all();
  }
}

}  // namespace edgeslam
