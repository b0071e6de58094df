#include "semantic/mask_propagator.h"

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

const cv::Matx23d kIdentity(1, 0, 0, 0, 1, 0);

cv::Matx33d homogeneous(const cv::Matx23d& w) {
  return cv::Matx33d(w(0, 0), w(0, 1), w(0, 2), w(1, 0), w(1, 1), w(1, 2), 0, 0, 1);
}

// The step from w0 to w1 (D = w1 * w0^-1, spanning the last step's frames) taken once more,
// scaled to `ratio` times its length: (I + ratio * (D - I)) * w1, the first-order power of D,
// close enough for the small rotations and scale changes of a few frames.
cv::Matx23d extrapolated(const cv::Matx23d& w0, const cv::Matx23d& w1, double ratio) {
  const cv::Matx33d h1 = homogeneous(w1);
  const cv::Matx33d step = h1 * homogeneous(w0).inv();
  const cv::Matx33d scaled = cv::Matx33d::eye() + ratio * (step - cv::Matx33d::eye());
  const cv::Matx33d next = scaled * h1;
  return cv::Matx23d(next(0, 0), next(0, 1), next(0, 2), next(1, 0), next(1, 1), next(1, 2));
}

cv::Point2f apply(const cv::Matx23d& w, cv::Point2f p) {
  return {static_cast<float>(w(0, 0) * p.x + w(0, 1) * p.y + w(0, 2)),
          static_cast<float>(w(1, 0) * p.x + w(1, 1) * p.y + w(1, 2))};
}

}  // namespace

MaskPropagator::MaskPropagator(MaskPropagatorOptions options) : options_(options) {
  warps_.fill(kIdentity);
  previous_warps_.fill(kIdentity);
  has_own_motion_.fill(false);
  last_step_frames_ = 0;
}

void MaskPropagator::setReference(cv::Mat1b labels, std::shared_ptr<const FrameFeatures> features) {
  if (labels.empty()) throw std::invalid_argument("mask propagation: empty keyframe label image");
  if (features == nullptr) throw std::invalid_argument("mask propagation: no keyframe features");
  labels_ = prepareLabels(std::move(labels), options_.transfer.near_margin_px);
  reference_ = std::move(features);
  warps_.fill(kIdentity);
  previous_warps_.fill(kIdentity);
  has_own_motion_.fill(false);
  last_step_frames_ = 0;
}

MaskTransferResult MaskPropagator::propagate(const FrameFeatures& current,
                                             std::size_t frames_since_last) {
  if (reference_ == nullptr) return {};
  if (!labels_.any) {
    // Nothing movable in the keyframe: nothing to move along.
    last_matches_ = {};
    MaskTransferResult nothing;
    nothing.labels = cv::Mat1b::zeros(labels_.labels.size());
    nothing.mask = nothing.labels.clone();
    return nothing;
  }
  std::array<cv::Matx23d, 256> predicted = warps_;
  if (last_step_frames_ > 0 && frames_since_last > 0) {
    // Constant velocity, scaled to this step's length (a late mask is carried in longer steps
    // than the one-frame steps that follow). Only the background and the labels present move;
    // the others are never looked up.
    const double ratio =
        static_cast<double>(frames_since_last) / static_cast<double>(last_step_frames_);
    for (std::size_t label = 0; label < predicted.size(); ++label) {
      if (label != 0 && labels_.boxes[label].empty()) continue;
      predicted[label] = extrapolated(previous_warps_[label], warps_[label], ratio);
    }
  }
  const MotionPrediction predict = [&predicted](std::uint8_t label, cv::Point2f p) {
    return apply(predicted[label], p);
  };
  const float radius =
      std::min(options_.max_search_radius_px,
               options_.search_radius_px +
                   options_.search_radius_per_frame_px *
                       static_cast<float>(frames_since_last > 0 ? frames_since_last - 1 : 0));
  last_matches_ = matchForTransfer(*reference_, labels_.labels_near, current, predict, radius,
                                   options_.matching);
  // Instances whose own motion is known keep it when their matches fail them.
  PredictedWarps own_prediction;
  for (std::size_t label = 1; label < own_prediction.size(); ++label) {
    if (has_own_motion_[label]) own_prediction[label] = predicted[label];
  }
  MaskTransferResult result = transferLabels(
      labels_, last_matches_.reference, last_matches_.current, options_.transfer, &own_prediction);
  previous_warps_ = warps_;
  last_step_frames_ = frames_since_last;
  for (cv::Matx23d& w : warps_) w = result.background.warp;
  for (const TransferredInstance& instance : result.instances) {
    warps_[instance.label] = instance.warp;
    has_own_motion_[instance.label] = instance.motion == InstanceMotion::kSimilarity ||
                                      instance.motion == InstanceMotion::kTranslation ||
                                      instance.motion == InstanceMotion::kPredicted;
  }
  return result;
}

}  // namespace edgeslam
