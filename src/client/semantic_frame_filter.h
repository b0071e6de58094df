#pragma once
// The client's semantic stage (paper Sec. IV-C): keyframe masks arrive later (from the edge, or
// from the in-process segmenter in local mode); each new frame gets the latest one transferred to
// it by feature matches, and its features inside the mask are culled before tracking sees them,
// so they neither track nor become map points.
//
// A mask usually arrives several frames after its keyframe. The thread that delivers it carries it
// forward over the frames seen since (a few steps through the recent frames' features, each a
// short motion), so the tracking thread only has to take it the last frame or two.
#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <memory>
#include <mutex>
#include <opencv2/core.hpp>
#include <optional>

#include "features/frame_features.h"
#include "geometry/camera.h"
#include "semantic/mask_propagator.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

struct SemanticFilterOptions {
  MaskPropagatorOptions propagation;
  int cull_margin_px = 4;  // features this close to the mask are culled too
  // Frames whose features are kept so that a late keyframe mask can still be transferred.
  std::size_t history_frames = 120;
  // A late mask is carried forward in steps of at most this many frames.
  std::size_t catch_up_step = 3;
};

struct SemanticFrame {
  std::shared_ptr<const FrameFeatures> all;      // every feature of the frame
  std::shared_ptr<const FrameFeatures> kept;     // those outside the mask (== all without a mask)
  cv::Mat1b mask;                                // transferred movable mask; empty before the first
  std::optional<std::size_t> mask_source_frame;  // the keyframe the mask came from
  int culled = 0;
  double elapsed_ms = 0.0;  // transfer and culling
};

struct SemanticFilterCounters {
  std::size_t masks_received = 0;
  std::size_t masks_applied = 0;
  std::size_t masks_too_old = 0;  // their keyframe had left the history
  // A newer keyframe's mask had come first (keyframes are segmented newest first): it serves the
  // map (its points on people leave), not tracking.
  std::size_t masks_superseded = 0;
  std::size_t frames_with_mask = 0;
  std::size_t frames_without_mask = 0;  // before the first mask came back
  std::size_t features_culled = 0;
  // How many frames after its keyframe the mask each frame got is: [age] up to 63, [64] beyond.
  std::array<std::uint64_t, 65> mask_age{};
};

class SemanticFrameFilter {
 public:
  explicit SemanticFrameFilter(const PinholeCamera& camera, SemanticFilterOptions options = {});

  // The label image (full image size) of the keyframe made from frame `frame_index`. Called from
  // the link's or the segmenter's thread (thread-safe); does the catch-up work there. The mask of
  // a frame not filtered yet (segmented before its features are culled) is kept for it.
  void offerMask(std::size_t frame_index, cv::Mat1b labels);

  // On the tracking thread, once per frame in order.
  SemanticFrame filter(std::size_t frame_index, std::shared_ptr<const FrameFeatures> all);

  SemanticFilterCounters counters() const;

  // The median of how many frames after their keyframe the last few masks arrived (nullopt
  // before the first).
  std::optional<std::size_t> typicalMaskDelayFrames() const;

 private:
  // A keyframe mask carried forward to `frame` by its own propagator.
  struct CarriedMask {
    std::size_t keyframe_frame = 0;
    std::size_t frame = 0;
    std::unique_ptr<MaskPropagator> propagator;
  };
  using History = std::deque<std::pair<std::size_t, std::shared_ptr<const FrameFeatures>>>;

  // A frame's own mask, offered before the frame was filtered.
  struct MaskAhead {
    std::size_t frame = 0;
    cv::Mat1b labels;
  };

  void takeCarriedMask();
  void cull(SemanticFrame& frame) const;  // the features of frame.all outside frame.mask
  void noteDelay(std::size_t frames) REQUIRES(mutex_);  // on the delivering thread

  PinholeCamera camera_;
  SemanticFilterOptions options_;

  // Tracking thread only.
  std::unique_ptr<MaskPropagator> propagator_;
  std::size_t source_frame_ = 0;  // keyframe of the mask in use
  std::size_t last_frame_ = 0;    // last frame the mask in use was carried to

  mutable Mutex mutex_;  // guards the fields below
  History history_ GUARDED_BY(mutex_);
  std::optional<CarriedMask> carried_ GUARDED_BY(mutex_);
  std::optional<MaskAhead> mask_ahead_ GUARDED_BY(mutex_);
  std::optional<std::size_t> newest_offered_ GUARDED_BY(mutex_);  // keyframe frame of the newest
  SemanticFilterCounters counters_ GUARDED_BY(mutex_);
  std::deque<std::size_t> recent_delays_ GUARDED_BY(mutex_);
  std::optional<std::size_t> typical_delay_
      GUARDED_BY(mutex_);  // their median, kept as they arrive
};

}  // namespace edgeslam
