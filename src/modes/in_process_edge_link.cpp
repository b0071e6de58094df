#include "modes/in_process_edge_link.h"

#include <spdlog/spdlog.h>

#include "semantic/keyframe_image.h"

namespace edgeslam {

InProcessEdgeLink::InProcessEdgeLink(const PinholeCamera& camera, Sensor sensor,
                                     EdgeMapSessionOptions options) {
  session_ = std::make_unique<EdgeMapSession>(camera, sensor, options, [this](MapSlice slice) {
    if (handler_) handler_(std::move(slice));
  });
  worker_ = std::thread([this] { run(); });
}

InProcessEdgeLink::~InProcessEdgeLink() {
  close();
}

void InProcessEdgeLink::send(KeyFrameUpload upload) {
  {
    MutexLock lock(mutex_);
    queue_.push_back(std::move(upload));
  }
  cv_.notify_one();
}

void InProcessEdgeLink::setUploadDroppedHandler(UploadDroppedHandler handler) {
  MutexLock lock(mutex_);
  dropped_handler_ = std::move(handler);
}

EdgeLinkCounters InProcessEdgeLink::counters() const {
  MutexLock lock(mutex_);
  EdgeLinkCounters out;
  out.uploads_dropped = uploads_dropped_;
  return out;
}

void InProcessEdgeLink::run() {
  while (true) {
    KeyFrameUpload upload;
    {
      MutexLock lock(mutex_);
      lock.wait(cv_, [this]() REQUIRES(mutex_) { return closing_ || !queue_.empty(); });
      if (queue_.empty()) return;
      upload = std::move(queue_.front());
      queue_.pop_front();
      busy_ = true;
    }
    bool rejected = false;
    try {
      compressKeyFrameImage(upload);
      session_->onKeyFrame(upload);
    } catch (const std::exception& e) {
      spdlog::error("edge session rejected keyframe upload {}: {}", upload.sequence, e.what());
      rejected = true;
    }
    if (rejected) {
      UploadDroppedHandler report;
      {
        MutexLock lock(mutex_);
        ++uploads_dropped_;
        report = dropped_handler_;
      }
      if (report) report(upload.sequence, upload.keyframe.id);
    }
    {
      MutexLock lock(mutex_);
      busy_ = false;
    }
    drained_.notify_all();
  }
}

void InProcessEdgeLink::flush() {
  MutexLock lock(mutex_);
  lock.wait(drained_, [this]() REQUIRES(mutex_) { return queue_.empty() && !busy_; });
  lock.unlock();
  session_->finish();
}

void InProcessEdgeLink::close() {
  {
    MutexLock lock(mutex_);
    if (closing_) return;
    closing_ = true;
  }
  cv_.notify_all();
  if (worker_.joinable()) worker_.join();
  session_->finish();
  session_->stop();
}

}  // namespace edgeslam
