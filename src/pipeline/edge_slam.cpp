#include "pipeline/edge_slam.h"

#include <spdlog/spdlog.h>

#include <thread>

#include "client/slice_applier.h"

namespace edgeslam {

EdgeSlam::EdgeSlam(const PinholeCamera& camera, SlamOptions options, std::unique_ptr<EdgeLink> link)
    : TrackingSlam(camera, std::move(options), link->idOrigin()), link_(std::move(link)) {
  sink_ = std::make_unique<EdgeKeyFrameSink>(map_, *link_);
  link_->setSliceHandler([this](MapSlice slice) { onSlice(std::move(slice)); });
  startTracking(sink_.get());
}

EdgeSlam::~EdgeSlam() {
  link_->close();
}

void EdgeSlam::onSlice(MapSlice slice) {
  Stopwatch apply_timer;
  const SliceApplyResult applied = applySlice(map_, slice, camera_);
  const double apply_ms = apply_timer.elapsedMs();
  spdlog::debug(
      "slice {} (keyframe of frame {}): {} points written, {} erased, {} poses, {:.1f} ms",
      slice.sequence, applied.frame_index, applied.points_upserted, applied.points_erased,
      applied.keyframes_moved, apply_ms);
  const double latency_s = sink_->onSliceApplied(slice.upload_sequence, applied.frame_index);
  std::lock_guard lock(stats_mutex_);
  ++slices_applied_;
  loops_ += slice.loops_closed;
  slice_apply_ms_.add(apply_ms);
  if (latency_s >= 0.0) slice_latency_ms_.add(latency_s * 1000.0);
}

void EdgeSlam::finish() {
  Stopwatch waited;
  while (!sink_->allAnswered()) {
    if (waited.elapsedMs() > finish_timeout_s * 1000.0) {
      spdlog::warn("edge: {} keyframe uploads still unanswered after {:.0f} s",
                   sink_->uploadsSent() - sink_->uploadsAnswered(), finish_timeout_s);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
}

SlamCounters EdgeSlam::counters() const {
  const EdgeLinkCounters link = link_->counters();
  SlamCounters out;
  out.uplink_bytes = link.uplink_bytes;
  out.downlink_bytes = link.downlink_bytes;
  out.uploads_dropped = link.uploads_dropped;
  out.reconnects = link.reconnects;
  out.keyframes_uploaded = sink_->uploadsSent();
  std::lock_guard lock(stats_mutex_);
  out.slices_applied = slices_applied_;
  out.loops = loops_;
  out.slice_latency_ms = slice_latency_ms_.summary();
  out.slice_apply_ms = slice_apply_ms_.summary();
  return out;
}

}  // namespace edgeslam
