#pragma once
// Carries a keyframe's movable-object labels forward to every following frame (paper Sec. IV-C):
// each frame's mask is transferred from the keyframe directly (no accumulated drift), by feature
// matches searched around where each instance's motion in the previous frame predicts them.
#include <array>
#include <cstdint>
#include <memory>
#include <opencv2/core.hpp>

#include "features/frame_features.h"
#include "semantic/mask_transfer.h"
#include "semantic/transfer_matching.h"

namespace edgeslam {

struct MaskPropagatorOptions {
  MaskTransferOptions transfer;
  TransferMatchOptions matching;
  float search_radius_px = 28.f;  // around the predicted position, one frame after the last
  // The search widens by this much per further frame since the last propagation (a late mask is
  // first carried to a frame some way past its keyframe), up to max_search_radius_px.
  float search_radius_per_frame_px = 8.f;
  float max_search_radius_px = 96.f;
  // An instance whose own motion is not known yet (the keyframe's first step, or after its
  // matches failed) is searched for at least this far: a person close to the camera crosses it
  // at 30 px a frame, beyond the radius above, and was then left behind where the keyframe saw
  // them (moved with the background).
  float unknown_motion_search_radius_px = 72.f;
  // How much an instance's apparent size may change per frame (someone walking at 1.4 m/s, 1.5 m
  // from the camera: ~3 %). Bounds the constant-velocity prediction, which would otherwise
  // compound a growth rate over every frame without matches (a mask grew to the whole image in
  // six frames and tracking was lost), and the similarities fitted against that prediction.
  double max_scale_change_per_frame = 1.08;
};

class MaskPropagator {
 public:
  explicit MaskPropagator(MaskPropagatorOptions options = {});

  // The labels (full image size, 0 = background) of the keyframe whose features are `features`.
  // Throws std::invalid_argument for an empty label image or features.
  void setReference(cv::Mat1b labels, std::shared_ptr<const FrameFeatures> features);
  bool hasReference() const { return reference_ != nullptr; }

  // The reference's labels moved to `current`, which comes `frames_since_last` frames after the
  // last frame propagated to (or the keyframe). Without a reference: empty labels and mask.
  MaskTransferResult propagate(const FrameFeatures& current, std::size_t frames_since_last = 1);
  // Matches used by the last propagation (for diagnostics).
  const TransferMatches& lastMatches() const { return last_matches_; }

 private:
  MaskPropagatorOptions options_;
  PreparedLabels labels_;
  std::shared_ptr<const FrameFeatures> reference_;
  // Per label ([0] background), keyframe -> the last frame propagated to, and -> the one before:
  // their difference is the label's motion, assumed to go on (constant velocity) when the next
  // step spans as many frames as the last.
  std::array<cv::Matx23d, 256> warps_;
  std::array<cv::Matx23d, 256> previous_warps_;
  // Labels whose last step was their own motion (fitted, or predicted from one): their
  // constant-velocity prediction stands in when their matches fail.
  std::array<bool, 256> has_own_motion_{};
  std::size_t last_step_frames_ = 0;
  TransferMatches last_matches_;
};

}  // namespace edgeslam
