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
  mapper_->setKeyFrameMappedCallback([this](KeyFrame* kf) { publishSlice(kf); });
  if (threaded_) mapper_->start();
}

EdgeMapSession::~EdgeMapSession() {
  stop();
}

void EdgeMapSession::stop() {
  mapper_->stop();
}

void EdgeMapSession::onKeyFrame(const KeyFrameUpload& upload) {
  KeyFrame* keyframe = nullptr;
  {
    std::lock_guard lock(map_.updateMutex());
    if (upload.map_reset) {
      mapper_->onMapReset();
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
    last_upload_sequence_ = upload.sequence;
    newest_keyframe_ = keyframe->id();
  }
  mapper_->insertKeyFrame(keyframe);
  if (!threaded_) mapper_->processAll();
}

void EdgeMapSession::publishSlice(KeyFrame* mapped) {
  MapSlice slice;
  {
    std::lock_guard lock(map_.updateMutex());
    slice = buildSlice(map_, map_.takeChanges());
    slice.processed_keyframe = mapped->id();
    if (!mapped->isBad()) {
      slice.reference_keyframe = mapped->id();
      slice.reference_pose = mapped->pose();
    }
    std::lock_guard state(state_mutex_);
    slice.sequence = ++slice_sequence_;
    slice.upload_sequence = last_upload_sequence_;
    slice.newest_keyframe = newest_keyframe_;
    ++stats_.slices;
    stats_.keyframes = map_.keyFrameCount();
    stats_.map_points = map_.pointCount();
  }
  if (publish_) publish_(std::move(slice));
}

void EdgeMapSession::finish() {
  mapper_->waitUntilIdle();
}

EdgeMapSessionStats EdgeMapSession::stats() const {
  std::lock_guard state(state_mutex_);
  return stats_;
}

}  // namespace edgeslam
