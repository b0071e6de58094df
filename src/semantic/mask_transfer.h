#pragma once
// Semantic mask transfer (paper Sec. IV-C, Fig. 9), improved: instead of copying the keyframe's
// mask, each instance is moved by its own motion, fitted to the feature matches that lie on it.
//
// Per instance (label) of the keyframe's label image, with the matches whose keyframe point lies
// on it (or, when none does, those within `near_margin_px` of it):
//  - at least `min_matches_for_warp` matches: RANSAC similarity (rotation, uniform scale,
//    translation) by cv::estimateAffinePartial2D; a fit with too few inliers or an implausible
//    scale change falls back to the next rule;
//  - at least `min_matches_for_translation` matches that agree (within
//    `translation_agreement_px` of their median, and at least min_inlier_ratio of them): the median
//    translation of those matches;
//  - otherwise: the instance's predicted motion when the caller has one (its own motion carried on
//    from the previous frames: a person walking out of the image, or behind something, keeps
//    going), else the background motion (a similarity fitted to the matches off every instance,
//    or their median translation, or the identity when there are none).
// The instance's pixels are warped (nearest neighbour, inside their bounding box only, so the cost
// follows the instance size) and painted into the current frame's label image.
//
// The matches should be the raw keyframe -> current feature matches, including features on the
// movable objects (before dynamic culling): those are what tell how the objects moved.
#include <array>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace edgeslam {

struct MaskTransferOptions {
  int near_margin_px = 12;       // matches this close to an instance count when none lies on it
  int min_matches_for_warp = 6;  // fewer: median translation instead of a similarity
  int min_matches_for_translation = 3;
  double translation_agreement_px = 6.0;
  double ransac_threshold_px = 3.0;
  double min_inlier_ratio = 0.5;  // of the matches used for the similarity
  double max_scale_change = 2.5;  // similarities scaling by more (or less than 1/this) are rejected
  // Where an instance has a predicted motion, a similarity whose scale differs from the
  // prediction's by more than this factor (or less than its inverse) is rejected too: a fit on
  // the last few matches of someone walking out of view can claim any size (0 = unchecked).
  double max_scale_change_from_prediction = 0.0;
  int ransac_iterations = 100;
  int merge_gap_px = 4;  // transferMask: mask fragments closer than this move as one instance
  // An instance cut by the keyframe's image edge grows back out past it as its motion brings
  // that edge into view (its pixels on the cut repeated outwards).
  bool grow_cut_edges = true;
};

// Where a warp (keyframe pixel -> current pixel) takes a point, and its scale (a similarity's
// uniform scale).
inline cv::Point2d warpPoint(const cv::Matx23d& w, const cv::Point2d& p) {
  return {w(0, 0) * p.x + w(0, 1) * p.y + w(0, 2), w(1, 0) * p.x + w(1, 1) * p.y + w(1, 2)};
}
inline double warpScale(const cv::Matx23d& w) {
  return std::hypot(w(0, 0), w(1, 0));
}

enum class InstanceMotion { kSimilarity, kTranslation, kPredicted, kBackground, kIdentity };

const char* toString(InstanceMotion motion);

struct TransferredInstance {
  std::uint8_t label = 0;
  InstanceMotion motion = InstanceMotion::kIdentity;
  cv::Matx23d warp = cv::Matx23d(1, 0, 0, 0, 1, 0);  // keyframe pixel -> current pixel
  int matches = 0;                                   // matches used for the fit
  int inliers = 0;
};

struct MaskTransferResult {
  cv::Mat1b labels;  // current frame label image, same size and labels as the keyframe's
  cv::Mat1b mask;    // union of the transferred instances, 255 inside
  std::vector<TransferredInstance> instances;  // ascending label
  TransferredInstance background;
};

// A keyframe's label image with what every transfer from it needs, computed once (transfers of
// one keyframe to many frames reuse it).
struct PreparedLabels {
  cv::Mat1b labels;
  cv::Mat1b labels_near;  // labels grown by near_margin_px (0 = background)
  int near_margin_px = 0;
  std::array<cv::Rect, 256> boxes;  // bounding box per label, empty where absent
  bool any = false;                 // some label present
};

// Throws std::invalid_argument for an empty image.
PreparedLabels prepareLabels(cv::Mat1b labels, int near_margin_px);

// `keyframe_points[i]` matches `current_points[i]` (pixels). Throws std::invalid_argument when the
// two lists differ in length.
MaskTransferResult transferLabels(const cv::Mat1b& keyframe_labels,
                                  const std::vector<cv::Point2f>& keyframe_points,
                                  const std::vector<cv::Point2f>& current_points,
                                  const MaskTransferOptions& options = {});
// Per label, the motion expected without matches (nullopt: none known).
using PredictedWarps = std::array<std::optional<cv::Matx23d>, 256>;

// The same from prepared labels (prepared with options.near_margin_px), with optional predicted
// motions for the instances whose own matches do not settle it.
MaskTransferResult transferLabels(const PreparedLabels& keyframe,
                                  const std::vector<cv::Point2f>& keyframe_points,
                                  const std::vector<cv::Point2f>& current_points,
                                  const MaskTransferOptions& options = {},
                                  const PredictedWarps* predicted = nullptr);

// The same for a binary movable mask: its connected components (fragments closer than
// `merge_gap_px` joined) are taken as the instances. Prefer transferLabels with the segmenter's
// label image where it is available: overlapping instances stay apart.
MaskTransferResult transferMask(const cv::Mat1b& keyframe_mask,
                                const std::vector<cv::Point2f>& keyframe_points,
                                const std::vector<cv::Point2f>& current_points,
                                const MaskTransferOptions& options = {});

}  // namespace edgeslam
