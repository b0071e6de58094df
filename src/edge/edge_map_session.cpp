#include "edge/edge_map_session.h"

#include <spdlog/spdlog.h>

#include <stdexcept>

#include "edge/slice_builder.h"
#include "map/map_replication.h"

namespace edgeslam {

EdgeMapSession::EdgeMapSession(const PinholeCamera& camera, Sensor sensor,
                               EdgeMapSessionOptions options, Publish publish)
    : camera_(camera), publish_(std::move(publish)), threaded_(options.threaded) {
  options.mapper.monocular = sensor == Sensor::kMonocular;
  mapper_ = std::make_unique<LocalMapper>(map_, camera_, options.mapper);
  if (options.vocabulary != nullptr && options.loop_closing) {
    LoopCloserOptions loop = loopCloserOptionsFor(sensor);
    loop.threaded = threaded_;
    loop_closer_ =
        std::make_unique<LoopCloser>(map_, camera_, options.vocabulary, loop, mapper_.get());
    loop_closer_->setMapCorrectedCallback([this] { publishSlice(nullptr); });
    loop_closer_->start();
  }
  mapper_->setKeyFrameMappedCallback([this](KeyFrame* kf) {
    publishSlice(kf);
    if (loop_closer_) loop_closer_->insertKeyFrame(kf);
  });
  if (threaded_) mapper_->start();
}

EdgeMapSession::~EdgeMapSession() {
  stop();
}

void EdgeMapSession::stop() {
  if (loop_closer_) loop_closer_->stop();
  mapper_->stop();
}

void EdgeMapSession::onKeyFrame(const KeyFrameUpload& upload) {
  KeyFrame* keyframe = nullptr;
  {
    std::lock_guard lock(map_.updateMutex());
    if (upload.map_reset) {
      mapper_->onMapReset();
      if (loop_closer_) loop_closer_->onMapReset();
      map_.clear();
    }
    // The client already has what it sent: apply it without recording it for the slices.
    map_.setChangeRecording(false);
    try {
      keyframe = insertKeyFrameRecord(map_, upload.keyframe, camera_);
      for (const MapPointRecord& point : upload.new_points) {
        if (map_.mapPoint(point.id) != nullptr) continue;
        // Normal, descriptor and distance range follow from the observations: the upload need
        // not carry them.
        if (MapPoint* p = upsertPointRecord(map_, point, upload.keyframe.id)) map_.refreshPoint(p);
      }
    } catch (...) {
      map_.setChangeRecording(true);
      throw;
    }
    map_.setChangeRecording(true);
    std::lock_guard state(state_mutex_);
    ++stats_.uploads;
    upload_of_keyframe_[keyframe->id()] = upload.sequence;
    newest_keyframe_ = keyframe->id();
  }
  mapper_->insertKeyFrame(keyframe);
  if (!threaded_) {
    mapper_->processAll();
    if (loop_closer_) loop_closer_->processAll();
  }
}

void EdgeMapSession::publishSlice(KeyFrame* mapped) {
  std::lock_guard publishing(publish_mutex_);
  MapSlice slice;
  {
    std::lock_guard lock(map_.updateMutex());
    const std::size_t loops = loop_closer_ ? loop_closer_->loops() : 0;
    if (mapped == nullptr && map_.changes().empty() && loops == loops_published_) return;
    slice = buildSlice(map_, map_.takeChanges());
    if (mapped != nullptr) {
      slice.processed_keyframe = mapped->id();
      if (!mapped->isBad()) {
        slice.reference_keyframe = mapped->id();
        slice.reference_pose = mapped->pose();
      }
    }
    slice.loops_closed = static_cast<std::uint32_t>(loops - loops_published_);
    loops_published_ = loops;
    std::lock_guard state(state_mutex_);
    slice.sequence = ++slice_sequence_;
    // A correction answers no upload.
    // The slice answers the upload of the keyframe it mapped (later uploads may be queued).
    slice.upload_sequence = 0;
    if (mapped != nullptr) {
      const auto it = upload_of_keyframe_.find(mapped->id());
      if (it != upload_of_keyframe_.end()) {
        slice.upload_sequence = it->second;
        upload_of_keyframe_.erase(it);
      }
    }
    slice.newest_keyframe = newest_keyframe_;
    ++stats_.slices;
    stats_.keyframes = map_.keyFrameCount();
    stats_.map_points = map_.pointCount();
  }
  if (publish_) publish_(std::move(slice));
}

void EdgeMapSession::finish() {
  mapper_->waitUntilIdle();
  if (loop_closer_) loop_closer_->waitUntilIdle();
}

EdgeMapSessionStats EdgeMapSession::stats() const {
  std::lock_guard state(state_mutex_);
  return stats_;
}

}  // namespace edgeslam
