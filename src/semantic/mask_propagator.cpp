#include "semantic/mask_propagator.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

const cv::Matx23d kIdentity(1, 0, 0, 0, 1, 0);

cv::Matx33d homogeneous(const cv::Matx23d& w) {
  return cv::Matx33d(w(0, 0), w(0, 1), w(0, 2), w(1, 0), w(1, 1), w(1, 2), 0, 0, 1);
}

cv::Matx23d affine(const cv::Matx33d& h) {
  return cv::Matx23d(h(0, 0), h(0, 1), h(0, 2), h(1, 0), h(1, 1), h(1, 2));
}

// `h` with its scale brought within [1/limit, limit], about `anchor` (in h's source): the anchor
// still goes where h takes it.
cv::Matx33d withScaleWithin(const cv::Matx33d& h, double limit, const cv::Point2d& anchor) {
  const double scale = warpScale(affine(h));
  const double bounded = std::clamp(scale, 1.0 / limit, limit);
  if (bounded == scale || scale <= 0.0) return h;
  const double f = bounded / scale;
  const cv::Point2d target = warpPoint(affine(h), anchor);
  cv::Matx33d out = h;
  for (int r = 0; r < 2; ++r) {
    for (int c = 0; c < 2; ++c) out(r, c) = f * h(r, c);
  }
  out(0, 2) = target.x - (out(0, 0) * anchor.x + out(0, 1) * anchor.y);
  out(1, 2) = target.y - (out(1, 0) * anchor.x + out(1, 1) * anchor.y);
  return out;
}

// The step from w0 to w1 (D = w1 * w0^-1, spanning the last step's frames) taken once more,
// scaled to `ratio` times its length: (I + ratio * (D - I)) * w1, the first-order power of D,
// close enough for the small rotations and scale changes of a few frames. The step's scale change
// is bounded by `step_scale_limit` and the result's (from the keyframe) by `total_scale_limit`,
// both about the instance's centre `anchor` (keyframe pixels).
cv::Matx23d extrapolated(const cv::Matx23d& w0, const cv::Matx23d& w1, double ratio,
                         double step_scale_limit, double total_scale_limit,
                         const cv::Point2d& anchor) {
  const cv::Matx33d h1 = homogeneous(w1);
  const cv::Matx33d step = h1 * homogeneous(w0).inv();
  const cv::Point2d anchor_now = warpPoint(w1, anchor);
  const cv::Matx33d scaled = withScaleWithin(
      cv::Matx33d::eye() + ratio * (step - cv::Matx33d::eye()), step_scale_limit, anchor_now);
  const cv::Matx33d next = withScaleWithin(scaled * h1, total_scale_limit, anchor);
  return affine(next);
}

cv::Point2f apply(const cv::Matx23d& w, cv::Point2f p) {
  const cv::Point2d q = warpPoint(w, cv::Point2d(p.x, p.y));
  return {static_cast<float>(q.x), static_cast<float>(q.y)};
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
  const double step_scale_limit =
      std::pow(std::max(1.0, options_.max_scale_change_per_frame),
               static_cast<double>(std::max<std::size_t>(1, frames_since_last)));
  if (last_step_frames_ > 0 && frames_since_last > 0) {
    // Constant velocity, scaled to this step's length (a late mask is carried in longer steps
    // than the one-frame steps that follow). Only the background and the labels present move;
    // the others are never looked up.
    const double ratio =
        static_cast<double>(frames_since_last) / static_cast<double>(last_step_frames_);
    const cv::Size image = labels_.labels.size();
    for (std::size_t label = 0; label < predicted.size(); ++label) {
      const cv::Rect& box = labels_.boxes[label];
      if (label != 0 && box.empty()) continue;
      const cv::Point2d centre =
          label == 0 ? cv::Point2d(image.width / 2.0, image.height / 2.0)
                     : cv::Point2d(box.x + box.width / 2.0, box.y + box.height / 2.0);
      predicted[label] = extrapolated(previous_warps_[label], warps_[label], ratio,
                                      step_scale_limit, options_.transfer.max_scale_change, centre);
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
  const SearchRadius radius_of = [&](std::uint8_t label) {
    if (label == 0 || has_own_motion_[label]) return radius;
    return std::max(radius, options_.unknown_motion_search_radius_px);
  };
  last_matches_ = matchForTransfer(*reference_, labels_.labels_near, current, predict, radius_of,
                                   options_.matching);
  // Instances whose own motion is known keep it when their matches fail them.
  PredictedWarps own_prediction;
  for (std::size_t label = 1; label < own_prediction.size(); ++label) {
    if (has_own_motion_[label]) own_prediction[label] = predicted[label];
  }
  MaskTransferOptions transfer = options_.transfer;
  transfer.max_scale_change_from_prediction = step_scale_limit;
  MaskTransferResult result = transferLabels(labels_, last_matches_.reference,
                                             last_matches_.current, transfer, &own_prediction);
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
