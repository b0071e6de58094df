#include "mapping/loop_closer.h"

#include <spdlog/spdlog.h>

#include <exception>

#include "mapping/loop_global_ba.h"
#include "util/timing_stats.h"

namespace edgeslam {

LoopCloserOptions loopCloserOptionsFor(Sensor sensor) {
  LoopCloserOptions options;
  const bool fix_scale = sensor != Sensor::kMonocular;
  options.verifier.fix_scale = fix_scale;
  options.correction.fix_scale = fix_scale;
  return options;
}

LoopCloser::LoopCloser(Map& map, const PinholeCamera& camera,
                       std::shared_ptr<const Vocabulary> vocabulary, LoopCloserOptions options,
                       LocalMapper* mapper)
    : map_(map),
      camera_(camera),
      options_(std::move(options)),
      map_participant_(map, "loop closing"),
      mapper_(mapper),
      detector_(std::move(vocabulary), options_.detector),
      queue_("loop closing", [this](KeyFrame* keyframe) { closeLoopsAt(keyframe); },
             {.capacity = 0,
              .thread_nice = options_.thread_nice,
              .on_failure = {},
              .group = {},
              .backlog = 0}) {}

LoopCloser::~LoopCloser() {
  stop();
}

void LoopCloser::start() {
  if (options_.threaded) queue_.start();
}

void LoopCloser::stop() {
  queue_.stop();
  stopGlobalBundleAdjustment();
}

void LoopCloser::insertKeyFrame(KeyFrame* keyframe) {
  queue_.push(keyframe);
}

void LoopCloser::onMapReset() {
  reset_requested_ = true;
  cancel_global_ba_ = true;  // no join: the caller may hold the map mutex the run needs
  queue_.clear();
}

LoopCloserStats LoopCloser::stats() const {
  MutexLock lock(stats_mutex_);
  return stats_;
}

std::vector<LoopEvent> LoopCloser::eventsFrom(std::size_t first) const {
  MutexLock lock(stats_mutex_);
  if (first >= stats_.events.size()) return {};
  return {stats_.events.begin() + static_cast<std::ptrdiff_t>(first), stats_.events.end()};
}

void LoopCloser::processAll() {
  if (options_.threaded) {
    waitUntilIdle();
    return;
  }
  queue_.processAll();
}

void LoopCloser::fileKeyFrame(KeyFrame* keyframe) {
  detector_.describe(*keyframe);
  MutexLock lock(map_.updateMutex());
  if (!keyframe->isBad()) detector_.detect(keyframe, map_, /*search=*/false, /*store=*/true);
}

void LoopCloser::waitUntilIdle() {
  if (options_.threaded) {
    queue_.waitUntilIdle();  // returns at once when not started
  } else {
    processAll();
  }
  MutexLock lock(global_ba_mutex_);
  global_ba_thread_.join();
}

std::optional<std::string> LoopCloser::failure() const {
  if (auto cause = queue_.failure()) return cause;
  MutexLock lock(global_ba_mutex_);
  return global_ba_thread_.failure();
}

void LoopCloser::closeLoopsAt(KeyFrame* keyframe) {
  processKeyFrame(keyframe);
  releaseErased();
}

void LoopCloser::releaseErased() {
  MutexLock lock(map_.updateMutex());
  // Erased keyframes leave the place database a few dozen at a time.
  constexpr std::size_t kForgetEvery = 32;
  if (detector_.describedCount() > map_.keyFrameCount() + kForgetEvery) {
    detector_.forgetIf([this](KeyFrameId id)
                           REQUIRES(map_.updateMutex()) { return map_.keyFrame(id) == nullptr; });
  }
  map_participant_.quiescent(map_);
}

void LoopCloser::processKeyFrame(KeyFrame* keyframe) {
  if (reset_requested_.exchange(false)) {
    detector_.clear();
    keyframes_since_loop_ = 0;
  }
  try {
    {
      MutexLock lock(map_.updateMutex());
      if (keyframe->isBad()) return;
    }
    const Stopwatch detection_timer;
    detector_.describe(*keyframe);  // the features never change: no lock needed
    ++keyframes_since_loop_;
    LoopVerification verification;
    bool verified_any = false;
    {
      MutexLock lock(map_.updateMutex());
      if (keyframe->isBad()) return;
      const bool search = map_.keyFrameCount() >= options_.min_map_keyframes &&
                          keyframes_since_loop_ > options_.min_keyframes_since_loop;
      const LoopDetection detection = detector_.detect(keyframe, map_, search);
      spdlog::debug(
          "loop detection: keyframe {} (frame {}): {} connections, min score {:.4f}, {} database "
          "hits, {} consistent candidates",
          keyframe->id(), keyframe->frameIndex(), keyframe->connections().size(),
          detection.min_score, detection.raw_candidates, detection.candidates.size());
      if (!detection.candidates.empty()) {
        verified_any = true;
        verification = verifyLoopCandidates(keyframe, detection.candidates, detector_, camera_,
                                            options_.verifier);
        for (const std::string& why : verification.rejections) {
          spdlog::debug("loop candidate for keyframe {} (frame {}) rejected: {}", keyframe->id(),
                        keyframe->frameIndex(), why);
        }
      }
    }
    {
      MutexLock lock(stats_mutex_);
      ++stats_.keyframes_processed;
      if (verified_any) ++stats_.keyframes_with_candidates;
      stats_.detection_ms.add(detection_timer.elapsedMs());
    }
    if (verification.loop) closeLoop(*verification.loop);
  } catch (const std::exception& e) {
    spdlog::error("loop closing: keyframe {} (frame {}): {}", keyframe->id(),
                  keyframe->frameIndex(), e.what());
  }
}

void LoopCloser::closeLoop(const VerifiedLoop& loop) {
  Stopwatch timer;
  // A global BA under way would undo this correction. It is cancelled, not waited for: one solver
  // iteration over a large map takes seconds, and its write-back checks the flag under the map
  // mutex (loop_global_ba.cpp). The next launch joins it.
  cancel_global_ba_ = true;
  if (mapper_ != nullptr) mapper_->pause();
  const double pause_ms = timer.elapsedMs();
  LoopCorrectionResult corrected;
  try {
    corrected = correctLoop(map_, loop, camera_, options_.correction, on_merged_);
  } catch (...) {
    if (mapper_ != nullptr) mapper_->resume();
    throw;
  }
  if (mapper_ != nullptr) mapper_->resume();
  const double elapsed_ms = timer.elapsedMs();
  if (!corrected.done) {
    spdlog::info("loop {} -> {}: keyframes culled before the correction, dropped",
                 loop.current->id(), loop.loop->id());
    return;
  }
  detector_.resetConsistency();
  keyframes_since_loop_ = 0;

  LoopEvent event;
  event.current = loop.current->id();
  event.loop = loop.loop->id();
  event.current_frame = loop.current->frameIndex();
  event.loop_frame = loop.loop->frameIndex();
  event.sim3_inliers = loop.sim3_inliers;
  event.matched_points = loop.matched_points;
  event.scale = corrected.scale;
  event.translation_m = corrected.translation_m;
  event.rotation_deg = corrected.rotation_deg;
  event.correction_ms = elapsed_ms;
  event.pose_graph_ms = corrected.pose_graph_ms;
  event.keyframes_merged = corrected.merged_keyframes_moved;
  if (event.keyframes_merged > 0) {
    spdlog::info(
        "maps merged: keyframe {} (frame {}) -> keyframe {} (frame {}): {} keyframes and {} "
        "points moved onto the other part of the map (scale {:.3f}{})",
        event.current, event.current_frame, event.loop, event.loop_frame,
        corrected.merged_keyframes_moved, corrected.merged_points_moved,
        corrected.merge.world.scale(),
        loop.scale_from_ranges ? ", from the points' ranges: the views meet at one place" : "");
  }
  spdlog::info(
      "loop closed: keyframe {} (frame {}) -> keyframe {} (frame {}): {} Sim3 inliers, {} points "
      "matched, scale {:.3f}, moved {:.3f} m / {:.2f} deg; {} keyframes corrected with it, {} "
      "points fused, {} new links; essential graph {} vertices {} edges {:.1f} ms; {:.1f} ms in "
      "all (local mapping paused in {:.1f} ms, graph built in {:.1f} ms, applied in {:.1f} ms)",
      event.current, event.current_frame, event.loop, event.loop_frame, event.sim3_inliers,
      event.matched_points, event.scale, event.translation_m, event.rotation_deg,
      corrected.neighbourhood, corrected.points_replaced, corrected.new_links,
      corrected.graph_vertices, corrected.graph_edges, corrected.pose_graph_ms, elapsed_ms,
      pause_ms, corrected.prepare_ms, corrected.apply_ms);
  {
    MutexLock lock(stats_mutex_);
    stats_.events.push_back(event);
    stats_.loops = stats_.events.size();
  }
  ++loops_;
  if (on_corrected_) on_corrected_();
  if (options_.global_ba) launchGlobalBundleAdjustment(event.current);
}

void LoopCloser::stopGlobalBundleAdjustment() {
  MutexLock lock(global_ba_mutex_);
  if (!global_ba_thread_.joinable()) return;
  cancel_global_ba_ = true;
  global_ba_thread_.join();
}

void LoopCloser::launchGlobalBundleAdjustment(KeyFrameId loop_keyframe) {
  {
    MutexLock lock(stats_mutex_);
    ++stats_.global_ba_started;
  }
  MutexLock lock(global_ba_mutex_);
  if (global_ba_thread_.joinable()) {
    Stopwatch wait;
    global_ba_thread_.join();  // cancelled by the loop that launches this one
    MutexLock stats_lock(stats_mutex_);
    stats_.global_ba_handover_ms.add(wait.elapsedMs());
  }
  cancel_global_ba_ = false;
  if (options_.threaded) {
    global_ba_thread_.start("global bundle adjustment", [this, loop_keyframe] {
      MapParticipant participant(map_, "global bundle adjustment");
      globalBundleAdjustment(loop_keyframe);
    });
  } else {
    globalBundleAdjustment(loop_keyframe);
  }
}

void LoopCloser::globalBundleAdjustment(KeyFrameId loop_keyframe) {
  Stopwatch timer;
  const KeyFrame* seed = nullptr;
  {
    MutexLock lock(map_.updateMutex());
    seed = map_.keyFrame(loop_keyframe);  // culled meanwhile: the whole map
  }
  GlobalBundleAdjustmentHooks hooks;
  if (mapper_ != nullptr) {
    hooks.before_apply = [this] { mapper_->pause(); };
    hooks.after_apply = [this] { mapper_->resume(); };
  }
  LoopGlobalBundleAdjustmentResult result;
  try {
    result = runLoopGlobalBundleAdjustment(map_, camera_, &cancel_global_ba_,
                                           options_.global_ba_iterations, hooks, seed,
                                           options_.global_ba_max_keyframes);
  } catch (const std::exception& e) {
    spdlog::error("global bundle adjustment failed: {}", e.what());
    return;
  }
  const double elapsed_ms = timer.elapsedMs();
  {
    MutexLock lock(stats_mutex_);
    if (result.applied) {
      ++stats_.global_ba_applied;
      stats_.global_ba_ms.push_back(elapsed_ms);
    } else if (result.cancelled) {
      ++stats_.global_ba_cancelled;
    } else if (result.too_large) {
      ++stats_.global_ba_too_large;
    }
  }
  if (result.too_large) {
    spdlog::info(
        "global bundle adjustment skipped: the loop's part of the map has {} keyframes (more than "
        "{}); the essential graph's correction stands",
        result.keyframes, options_.global_ba_max_keyframes);
    return;
  }
  if (result.cancelled) {
    spdlog::info("global bundle adjustment abandoned after {:.0f} ms", elapsed_ms);
    return;
  }
  spdlog::info(
      "global bundle adjustment: {} keyframes, {} points, {} observations, {} iterations, rms "
      "{:.3f} -> {:.3f}, {} outliers removed, {} keyframes made meanwhile; {:.0f} ms",
      result.keyframes, result.points, result.observations, result.iterations, result.rms_before,
      result.rms_after, result.outliers_removed, result.keyframes_propagated, elapsed_ms);
  if (result.applied && on_corrected_) on_corrected_();
}

}  // namespace edgeslam
