#include "client/semantic_frame_filter.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <stdexcept>
#include <vector>

#include "semantic/feature_subset.h"
#include "semantic/mask_query.h"
#include "util/timing_stats.h"

namespace edgeslam {

SemanticFrameFilter::SemanticFrameFilter(const PinholeCamera& camera, SemanticFilterOptions options)
    : camera_(camera), options_(options) {}

void SemanticFrameFilter::offerMask(std::size_t frame_index, cv::Mat1b labels) {
  if (labels.empty()) throw std::invalid_argument("semantic filter: empty keyframe mask");
  if (labels.cols != camera_.width() || labels.rows != camera_.height()) {
    throw std::invalid_argument(fmt::format("semantic filter: mask is {}x{}, the camera {}x{}",
                                            labels.cols, labels.rows, camera_.width(),
                                            camera_.height()));
  }
  History since;  // the keyframe and the frames after it
  {
    MutexLock lock(mutex_);
    ++counters_.masks_received;
    if (newest_offered_ && *newest_offered_ > frame_index) {
      ++counters_.masks_superseded;
      return;
    }
    newest_offered_ = frame_index;
    if (history_.empty() || frame_index > history_.back().first) {
      // The frame's own mask, made before the frame is filtered: applied as it is then.
      noteDelay(0);
      mask_ahead_ = MaskAhead{frame_index, std::move(labels)};
      return;
    }
    for (const auto& entry : history_) {
      if (entry.first >= frame_index) since.push_back(entry);
    }
    const bool too_old = since.empty() || since.front().first != frame_index;
    noteDelay(too_old ? options_.history_frames : since.back().first - frame_index);
    if (too_old) {
      ++counters_.masks_too_old;
      spdlog::debug("mask of frame {} arrived past the history", frame_index);
      return;
    }
  }
  spdlog::debug("mask of keyframe frame {} arrived at frame {} ({} frames late)", frame_index,
                since.back().first, since.back().first - frame_index);
  CarriedMask carried;
  carried.keyframe_frame = frame_index;
  carried.frame = frame_index;
  carried.propagator = std::make_unique<MaskPropagator>(options_.propagation);
  carried.propagator->setReference(std::move(labels), since.front().second);
  // A first step of one frame measures how each instance moves; then steps of at most
  // catch_up_step frames, each searched around where that motion predicts the features, ending
  // on the newest frame seen. (Without the first short step a person walking 15 px per frame is
  // searched for around where they stood, and the mask is lost.)
  const std::size_t step = std::max<std::size_t>(1, options_.catch_up_step);
  for (std::size_t k = 1; k < since.size(); ++k) {
    const bool last = k + 1 == since.size();
    const bool first = carried.frame == frame_index;
    if (!last && !first && since[k].first - carried.frame < step) continue;
    carried.propagator->propagate(*since[k].second, since[k].first - carried.frame);
    carried.frame = since[k].first;
  }
  MutexLock lock(mutex_);
  // Only the newest keyframe's mask matters.
  if (carried_ && carried_->keyframe_frame > frame_index) return;
  carried_ = std::move(carried);
}

void SemanticFrameFilter::takeCarriedMask() {
  std::optional<CarriedMask> carried;
  {
    MutexLock lock(mutex_);
    carried.swap(carried_);
  }
  // An older keyframe's mask than the one in use brings nothing new.
  if (!carried || (propagator_ && source_frame_ >= carried->keyframe_frame)) return;
  propagator_ = std::move(carried->propagator);
  source_frame_ = carried->keyframe_frame;
  last_frame_ = carried->frame;
  MutexLock lock(mutex_);
  ++counters_.masks_applied;
}

SemanticFrame SemanticFrameFilter::filter(std::size_t frame_index,
                                          std::shared_ptr<const FrameFeatures> all) {
  Stopwatch timer;
  SemanticFrame out;
  out.all = all;
  out.kept = all;
  takeCarriedMask();
  std::optional<MaskAhead> ahead;
  {
    MutexLock lock(mutex_);
    if (mask_ahead_ && mask_ahead_->frame <= frame_index) ahead.swap(mask_ahead_);
  }
  if (ahead && ahead->frame == frame_index) {
    out.mask = ahead->labels > 0;
    out.mask_source_frame = frame_index;
    propagator_ = std::make_unique<MaskPropagator>(options_.propagation);
    propagator_->setReference(std::move(ahead->labels), all);
    source_frame_ = frame_index;
    last_frame_ = frame_index;
    cull(out);
    MutexLock lock(mutex_);
    ++counters_.masks_applied;
  } else if (propagator_ && frame_index > last_frame_) {
    MaskTransferResult transferred = propagator_->propagate(*all, frame_index - last_frame_);
    last_frame_ = frame_index;
    out.mask = std::move(transferred.mask);
    out.mask_source_frame = source_frame_;
    cull(out);
  }
  out.elapsed_ms = timer.elapsedMs();
  MutexLock lock(mutex_);
  history_.emplace_back(frame_index, std::move(all));
  while (history_.size() > options_.history_frames) history_.pop_front();
  counters_.frames_with_mask += !out.mask.empty();
  counters_.frames_without_mask += out.mask.empty();
  if (out.mask_source_frame) {
    const std::size_t age = frame_index - std::min(frame_index, *out.mask_source_frame);
    ++counters_.mask_age[std::min<std::size_t>(age, counters_.mask_age.size() - 1)];
  }
  counters_.features_culled += static_cast<std::size_t>(out.culled);
  return out;
}

void SemanticFrameFilter::cull(SemanticFrame& frame) const {
  const std::vector<int> keep =
      indicesOutsideMask(frame.all->keypoints, frame.mask, options_.cull_margin_px);
  frame.culled = static_cast<int>(frame.all->size() - keep.size());
  if (frame.culled > 0) frame.kept = selectFeatures(*frame.all, keep, camera_);
}

void SemanticFrameFilter::noteDelay(std::size_t frames) {
  constexpr std::size_t kRecentMasks = 5;
  recent_delays_.push_back(frames);
  while (recent_delays_.size() > kRecentMasks) recent_delays_.pop_front();
  std::vector<std::size_t> delays(recent_delays_.begin(), recent_delays_.end());
  const auto middle = delays.begin() + static_cast<std::ptrdiff_t>(delays.size() / 2);
  std::nth_element(delays.begin(), middle, delays.end());
  typical_delay_ = *middle;
}

std::optional<std::size_t> SemanticFrameFilter::typicalMaskDelayFrames() const {
  MutexLock lock(mutex_);
  return typical_delay_;
}

SemanticFilterCounters SemanticFrameFilter::counters() const {
  MutexLock lock(mutex_);
  return counters_;
}

}  // namespace edgeslam
