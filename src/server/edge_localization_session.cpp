#include "server/edge_localization_session.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>

#include "map/map_replication.h"

namespace edgeslam {
namespace {

ClientMapWindowOptions localizationWindow(std::size_t keyframes) {
  ClientMapWindowOptions window;
  window.keyframes = keyframes;
  // A stored map's newest keyframes are not near the client: only covisibility counts.
  window.recent_share = 0.0;
  // The client has nothing to track against until its first window is whole.
  window.max_entering_per_slice = keyframes;
  return window;
}

}  // namespace

EdgeLocalizationSession::EdgeLocalizationSession(const PinholeCamera& camera,
                                                 EdgeLocalizationSessionOptions options,
                                                 const std::function<void(Map&)>& load,
                                                 Publish publish)
    : camera_(camera),
      options_(std::move(options)),
      window_(localizationWindow(std::max<std::size_t>(1, options_.window_keyframes))),
      publish_(std::move(publish)) {
  if (options_.vocabulary == nullptr || options_.vocabulary->empty()) {
    throw std::invalid_argument(
        "localisation through the edge needs a vocabulary on the edge (edgeslam server --vocab)");
  }
  if (load) load(map_);
  MutexLock lock(map_.updateMutex());
  places_ = std::make_unique<KeyFramePlaces>(options_.vocabulary);
  std::size_t filed = 0;
  for (KeyFrame* keyframe : map_.keyFrames()) {
    if (keyframe->isBad()) continue;
    places_->addDescribed(*keyframe);
    ++filed;
  }
  if (filed == 0) throw std::invalid_argument("the stored map has no keyframes to localise in");
}

void EdgeLocalizationSession::onQuery(const KeyFrameUpload& upload) {
  if (!upload.localization_query) {
    throw std::invalid_argument("a localise-only session takes localisation queries only");
  }
  const Stopwatch timer;
  const KeyFrameRecord& asked = upload.keyframe;
  LocalizationAnswer answer;
  answer.frame_index = asked.frame_index;
  MapSlice slice;
  bool relocalizing = false;
  {
    MutexLock lock(map_.updateMutex());
    KeyFrame* centre = nullptr;
    if (asked.parent != kInvalidId) {
      centre = map_.keyFrame(asked.parent);
      if (centre != nullptr && centre->isBad()) centre = nullptr;
    } else if (!asked.features.keypoints.empty()) {
      relocalizing = true;
      Frame frame(asked.frame_index, asked.timestamp, featuresFromRecord(asked.features, camera_),
                  &camera_);
      std::vector<KeyFrame*> candidates;
      for (KeyFrameId id : places_->similar(*frame.features, options_.relocalization_candidates)) {
        KeyFrame* kf = map_.keyFrame(id);
        if (kf != nullptr && !kf->isBad()) candidates.push_back(kf);
      }
      const FrameRelocalization found =
          relocalizeFrame(frame, candidates, places_.get(), camera_, options_.relocalization);
      answer.candidates = static_cast<std::uint32_t>(found.candidates_tried);
      if (found.keyframe != nullptr) {
        centre = found.keyframe;
        answer.T_cw = frame.T_cw;
        answer.inliers = static_cast<std::uint32_t>(found.inliers);
      }
    }
    if (centre != nullptr) {
      answer.found = true;
      answer.keyframe = centre->id();
      window_.shape(map_, centre, slice);
    }
    slice.map_keyframes = map_.keyFrameCount();
    slice.map_points = map_.pointCount();
  }
  answer.edge_ms = timer.elapsedMs();
  if (relocalizing) {
    spdlog::debug("localisation: frame {} {} in {:.1f} ms ({} candidates, {} inliers)",
                  answer.frame_index, answer.found ? "relocalised" : "not found", answer.edge_ms,
                  answer.candidates, answer.inliers);
  }
  slice.upload_sequence = upload.sequence;
  {
    MutexLock state(state_mutex_);
    ++stats_.queries;
    if (relocalizing) {
      ++stats_.relocalization_queries;
      stats_.relocalized += answer.found ? 1 : 0;
      stats_.relocalization_ms.add(answer.edge_ms);
    } else {
      stats_.window_moves += answer.found ? 1 : 0;
    }
    stats_.keyframes_sent += slice.keyframes.size();
  }
  slice.localization = answer;
  publish(std::move(slice));
}

void EdgeLocalizationSession::publishFullResync() {
  MapSlice slice;
  slice.full_resync = true;
  {
    MutexLock lock(map_.updateMutex());
    window_.clear();
    slice.map_keyframes = map_.keyFrameCount();
    slice.map_points = map_.pointCount();
  }
  publish(std::move(slice));
}

void EdgeLocalizationSession::publish(MapSlice slice) {
  {
    MutexLock state(state_mutex_);
    slice.sequence = ++slice_sequence_;
    ++stats_.slices;
  }
  // Sequence order is publication order: one query at a time per session (the service holds the
  // session's backend mutex around each upload).
  if (publish_) publish_(std::move(slice));
}

EdgeLocalizationStats EdgeLocalizationSession::stats() const {
  MutexLock state(state_mutex_);
  return stats_;
}

std::size_t EdgeLocalizationSession::keyFrameCount() const {
  MutexLock lock(map_.updateMutex());
  return map_.keyFrameCount();
}

}  // namespace edgeslam
