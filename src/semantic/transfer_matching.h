#pragma once
// Feature matches between a keyframe (whose mask is known) and the current frame, for mask
// transfer: every keyframe feature on or near a movable instance, plus a sample of the
// background, is searched for around where its instance's last motion predicts it, by descriptor.
// Unlike tracking's matches these include the features on the moving objects: they are what tells
// how the objects moved.
#include <cstdint>
#include <functional>
#include <opencv2/core.hpp>
#include <vector>

#include "features/frame_features.h"

namespace edgeslam {

struct TransferMatchOptions {
  int max_descriptor_distance = 64;
  float ratio = 0.9f;         // best distance below ratio * second best (different positions)
  int background_stride = 4;  // every n-th background feature is searched for
  int level_window = 1;       // pyramid levels either side of the keyframe feature's
};

struct TransferMatches {
  std::vector<cv::Point2f> reference;  // keyframe pixels
  std::vector<cv::Point2f> current;    // matching current-frame pixels
  int on_instances = 0;                // matches whose keyframe feature has a label
};

// Predicted current position of a keyframe pixel on instance `label` (0 = background).
using MotionPrediction = std::function<cv::Point2f(std::uint8_t label, cv::Point2f reference)>;

// How far around its predicted position a keyframe feature on `label` is searched for (pixels).
using SearchRadius = std::function<float(std::uint8_t label)>;

// `labels_near` is the keyframe's label image grown by the margin within which a feature counts
// as on an instance. Each current feature is used at most once (the closer descriptor wins).
TransferMatches matchForTransfer(const FrameFeatures& reference, const cv::Mat1b& labels_near,
                                 const FrameFeatures& current, const MotionPrediction& predict,
                                 const SearchRadius& radius,
                                 const TransferMatchOptions& options = {});
// The same radius for every label.
TransferMatches matchForTransfer(const FrameFeatures& reference, const cv::Mat1b& labels_near,
                                 const FrameFeatures& current, const MotionPrediction& predict,
                                 float search_radius_px, const TransferMatchOptions& options = {});

}  // namespace edgeslam
