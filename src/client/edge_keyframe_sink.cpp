#include "client/edge_keyframe_sink.h"

#include "map/map_replication.h"

namespace edgeslam {

EdgeKeyFrameSink::EdgeKeyFrameSink(Map& map, KeyFrameUplink& uplink,
                                   EdgeKeyFrameSinkOptions options)
    : map_(map), uplink_(uplink), options_(options) {}

void EdgeKeyFrameSink::insertKeyFrame(KeyFrame* keyframe) {
  KeyFrameUpload upload;
  {
    std::lock_guard lock(map_.updateMutex());
    if (keyframe->isBad()) return;
    upload.keyframe = keyFrameRecord(*keyframe);
    const std::uint8_t own_origin = idOrigin(keyframe->id());
    for (MapPoint* p : keyframe->goodPoints()) {
      if (idOrigin(p->id()) != own_origin || uploaded_points_.contains(p->id())) continue;
      MapPointRecord record = mapPointRecord(*p);
      record.position_from_depth =
          options_.camera.has_value() && isDepthBackProjection(*p, *keyframe, *options_.camera);
      upload.new_points.push_back(std::move(record));
      uploaded_points_.insert(p->id());
    }
    upload.segmenter_nms = segmenter_nms_.load();
    upload.map_reset = reset_pending_;
    reset_pending_ = false;
    if (!image_.empty() && image_frame_ == keyframe->frameIndex()) upload.raw_image = image_;
  }
  upload.sequence = sequence_.load() + 1;
  {
    std::lock_guard lock(sent_mutex_);
    sent_times_.emplace_back(upload.sequence, Clock::now());
    if (sent_times_.size() > 256) sent_times_.pop_front();
  }
  sequence_ = upload.sequence;
  uplink_.send(std::move(upload));
}

void EdgeKeyFrameSink::attachImage(std::size_t frame_index, cv::Mat image) {
  image_frame_ = frame_index;
  image_ = std::move(image);
}

bool EdgeKeyFrameSink::acceptsKeyFrames() const {
  return sequence_.load() - answered_.load() < options_.max_in_flight;
}

bool EdgeKeyFrameSink::acceptsUrgentKeyFrames() const {
  return sequence_.load() - answered_.load() <
         options_.max_in_flight + options_.urgent_extra_in_flight;
}

void EdgeKeyFrameSink::onMapReset() {
  std::lock_guard lock(map_.updateMutex());
  reset_pending_ = true;
  uploaded_points_.clear();
  // The edge drops what it had not mapped yet: no slice will answer those uploads.
  answered_ = sequence_.load();
}

double EdgeKeyFrameSink::onSliceApplied(std::uint64_t upload_sequence,
                                        std::size_t processed_frame_index) {
  if (upload_sequence > answered_.load()) answered_ = upload_sequence;
  if (processed_frame_index > last_optimized_frame_.load()) {
    last_optimized_frame_ = processed_frame_index;
  }
  std::lock_guard lock(sent_mutex_);
  for (const auto& [sequence, sent_at] : sent_times_) {
    if (sequence == upload_sequence) {
      return std::chrono::duration<double>(Clock::now() - sent_at).count();
    }
  }
  return -1.0;
}

}  // namespace edgeslam
