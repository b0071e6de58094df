#include "client/edge_keyframe_sink.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "map/map_replication.h"

namespace edgeslam {

EdgeKeyFrameSink::EdgeKeyFrameSink(Map& map, KeyFrameUplink& uplink,
                                   EdgeKeyFrameSinkOptions options)
    : map_(map), uplink_(uplink), options_(options) {}

void EdgeKeyFrameSink::insertKeyFrame(KeyFrame* keyframe) {
  sendUpload(keyframe, false);
}

bool EdgeKeyFrameSink::resendKeyFrame(KeyFrameId id) {
  KeyFrame* keyframe = nullptr;
  {
    MutexLock lock(map_.updateMutex());
    keyframe = map_.keyFrame(id);
    if (keyframe == nullptr || keyframe->isBad() || keyframe->isEvicted()) return false;
  }
  sendUpload(keyframe, true);
  ++keyframes_resent_;
  return true;
}

void EdgeKeyFrameSink::sendUpload(KeyFrame* keyframe, bool resend) {
  KeyFrameUpload upload;
  {
    MutexLock lock(map_.updateMutex());
    if (keyframe->isBad()) return;
    upload.keyframe = keyFrameRecord(*keyframe);
    const std::uint8_t own_origin = idOrigin(keyframe->id());
    for (MapPoint* p : keyframe->goodPoints()) {
      if (idOrigin(p->id()) != own_origin || (!resend && uploaded_points_.contains(p->id()))) {
        continue;
      }
      MapPointRecord record = mapPointRecord(*p);
      record.position_from_depth =
          options_.camera.has_value() && isDepthBackProjection(*p, *keyframe, *options_.camera);
      upload.new_points.push_back(std::move(record));
      uploaded_points_.insert(p->id());
    }
    // Points the map has erased since cannot be uploaded again: forgotten a few thousand at a time,
    // so that what a long session remembers follows what its map holds.
    if (uploaded_points_.size() > 2 * map_.pointCount() + kForgetUploadedPointsEvery) {
      std::erase_if(uploaded_points_, [this](MapPointId id) REQUIRES(map_.updateMutex()) {
        return map_.mapPoint(id) == nullptr;
      });
    }
    upload.segmenter_nms = segmenter_nms_.load();
    if (!resend) {
      upload.map_reset = reset_pending_;
      reset_pending_ = false;
      if (!image_.empty() && image_frame_ == keyframe->frameIndex()) upload.raw_image = image_;
    }
    upload.sequence = sequence_.load() + 1;
    UploadRecord record{upload.sequence, keyframe->id(), {}, upload.map_reset};
    record.new_points.reserve(upload.new_points.size());
    for (const MapPointRecord& p : upload.new_points) record.new_points.push_back(p.id);
    recent_uploads_.push_back(std::move(record));
    if (recent_uploads_.size() > kRememberedUploads) recent_uploads_.pop_front();
    // Set under the lock, so that onUploadDropped sees whether a later upload was built.
    sequence_ = upload.sequence;
    if (resend || uplink_.reconnecting()) backlog_last_sequence_ = upload.sequence;
  }
  {
    MutexLock lock(sent_mutex_);
    sent_times_.emplace_back(upload.sequence, Clock::now());
    if (sent_times_.size() > 256) sent_times_.pop_front();
  }
  uplink_.send(std::move(upload));
}

void EdgeKeyFrameSink::attachImage(std::size_t frame_index, cv::Mat image) {
  image_frame_ = frame_index;
  image_ = std::move(image);
}

std::uint64_t EdgeKeyFrameSink::uploadsInFlight() const {
  return inFlightAbove(0);
}

std::uint64_t EdgeKeyFrameSink::uploadsInFlightAfterBacklog() const {
  return inFlightAbove(backlog_last_sequence_.load());
}

std::uint64_t EdgeKeyFrameSink::inFlightAbove(std::uint64_t floor) const {
  MutexLock lock(sent_mutex_);
  const std::uint64_t sent = sequence_.load();
  const std::uint64_t answered = std::max(answered_.load(), floor);
  if (sent <= answered) return 0;
  const auto dropped = static_cast<std::uint64_t>(std::count_if(
      dropped_unanswered_.begin(), dropped_unanswered_.end(),
      [&](std::uint64_t sequence) { return sequence > answered && sequence <= sent; }));
  return sent - answered - std::min(dropped, sent - answered);
}

bool EdgeKeyFrameSink::withinBounds(std::size_t limit) const {
  if (uplink_.reconnecting()) return uploadsInFlight() < options_.max_in_flight_reconnecting;
  return uploadsInFlightAfterBacklog() < limit &&
         uploadsInFlight() < std::max(limit, options_.max_in_flight_reconnecting);
}

bool EdgeKeyFrameSink::acceptsKeyFrames() const {
  return withinBounds(options_.max_in_flight);
}

bool EdgeKeyFrameSink::acceptsUrgentKeyFrames() const {
  return withinBounds(options_.max_in_flight + options_.urgent_extra_in_flight);
}

void EdgeKeyFrameSink::onMapReset() {
  MutexLock lock(map_.updateMutex());
  reset_pending_ = true;
  uploaded_points_.clear();
  recent_uploads_.clear();  // the map they were made in is gone: nothing to forget
  // The edge drops what it had not mapped yet: no slice will answer those uploads.
  answered_ = sequence_.load();
}

double EdgeKeyFrameSink::onSliceApplied(std::uint64_t upload_sequence,
                                        std::size_t processed_frame_index) {
  if (processed_frame_index > last_optimized_frame_.load()) {
    last_optimized_frame_ = processed_frame_index;
  }
  MutexLock lock(sent_mutex_);
  if (upload_sequence > answered_.load()) answered_ = upload_sequence;
  std::erase_if(dropped_unanswered_,
                [&](std::uint64_t sequence) { return sequence <= answered_.load(); });
  for (const auto& [sequence, sent_at] : sent_times_) {
    if (sequence == upload_sequence) {
      return std::chrono::duration<double>(Clock::now() - sent_at).count();
    }
  }
  return -1.0;
}

bool EdgeKeyFrameSink::onUploadDropped(std::uint64_t upload_sequence, KeyFrameId keyframe_id) {
  {
    MutexLock lock(sent_mutex_);
    if (upload_sequence > answered_.load()) dropped_unanswered_.insert(upload_sequence);
  }
  MutexLock lock(map_.updateMutex());
  KeyFrame* keyframe = map_.keyFrame(keyframe_id);
  std::vector<MapPointId> unknown_points;
  const auto record =
      std::find_if(recent_uploads_.begin(), recent_uploads_.end(), [&](const UploadRecord& r) {
        return r.sequence == upload_sequence && r.keyframe == keyframe_id;
      });
  if (record != recent_uploads_.end()) {
    unknown_points = std::move(record->new_points);
    if (record->map_reset) {
      // The edge never heard of the reset. Said again with the next upload when none was built
      // since; otherwise the uploads after it already went out as the old map's continuation.
      if (upload_sequence == sequence_.load()) {
        reset_pending_ = true;
      } else {
        spdlog::warn("edge: upload {} that started a new map was dropped", upload_sequence);
      }
    }
    recent_uploads_.erase(record);
  } else if (keyframe != nullptr) {
    // Older than the uploads remembered: the points it made itself went up with it.
    for (MapPoint* p : keyframe->goodPoints()) {
      if (p->firstKeyFrameId() == keyframe_id) unknown_points.push_back(p->id());
    }
  }

  std::uint64_t points_forgotten = 0;
  KeyFrameSet observers;
  for (MapPointId id : unknown_points) {
    uploaded_points_.erase(id);
    MapPoint* p = map_.mapPoint(id);
    if (p == nullptr || p->isBad()) continue;
    for (const auto& [observer_id, observation] : p->observations()) {
      observers.insert(observation.keyframe);
    }
    map_.erasePoint(p);
    ++points_forgotten;
  }
  bool forgotten = false;
  if (keyframe != nullptr && !keyframe->isBad()) {
    // Detached first: eraseKeyFrame would also cull points the edge knows that are left with a
    // single observation, and the edge would not send them again.
    const std::vector<MapPoint*> seen = keyframe->points();
    for (MapPoint* p : seen) {
      if (p != nullptr && !p->isBad()) map_.detachObservation(p, keyframe);
    }
    map_.eraseKeyFrame(keyframe);
    // The origin cannot be erased (poses hang from it): it keeps its pose only, as an evicted
    // keyframe does.
    if (!keyframe->isBad()) map_.evictKeyFrame(keyframe);
    forgotten = true;
  }
  for (KeyFrame* observer : observers) {
    if (observer != keyframe && !observer->isBad() && !observer->isEvicted()) {
      map_.updateConnections(observer);
    }
  }
  points_forgotten_ += points_forgotten;
  if (forgotten) ++keyframes_forgotten_;
  spdlog::debug("edge: upload {} dropped: keyframe {:#x} {}, {} of its points forgotten",
                upload_sequence, keyframe_id, forgotten ? "forgotten" : "already gone",
                points_forgotten);
  return forgotten;
}

}  // namespace edgeslam
