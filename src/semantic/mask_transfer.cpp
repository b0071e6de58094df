#include "semantic/mask_transfer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace edgeslam {
namespace {

constexpr int kLabels = 256;

struct InstanceExtent {
  int min_x = INT32_MAX, min_y = INT32_MAX, max_x = -1, max_y = -1;
  bool present() const { return max_x >= 0; }
  cv::Rect rect() const { return {min_x, min_y, max_x - min_x + 1, max_y - min_y + 1}; }
};

std::array<InstanceExtent, kLabels> instanceExtents(const cv::Mat1b& labels) {
  std::array<InstanceExtent, kLabels> extents;
  for (int y = 0; y < labels.rows; ++y) {
    const std::uint8_t* row = labels.ptr<std::uint8_t>(y);
    for (int x = 0; x < labels.cols; ++x) {
      if (row[x] == 0) continue;
      InstanceExtent& e = extents[row[x]];
      e.min_x = std::min(e.min_x, x);
      e.max_x = std::max(e.max_x, x);
      e.min_y = std::min(e.min_y, y);
      e.max_y = std::max(e.max_y, y);
    }
  }
  return extents;
}

double median(std::vector<double> values) {
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

cv::Matx23d translation(double tx, double ty) {
  return cv::Matx23d(1, 0, tx, 0, 1, ty);
}

// Fits the motion of one set of matched points by the rules in mask_transfer.h; `fallback` is used
// when there are no matches.
TransferredInstance fitMotion(const std::vector<cv::Point2f>& from,
                              const std::vector<cv::Point2f>& to,
                              const MaskTransferOptions& options,
                              const TransferredInstance& fallback) {
  TransferredInstance fit = fallback;
  fit.matches = static_cast<int>(from.size());
  fit.inliers = 0;
  if (from.empty()) return fit;
  if (static_cast<int>(from.size()) >= options.min_matches_for_warp) {
    std::vector<std::uint8_t> inlier_flags;
    const cv::Mat warp =
        cv::estimateAffinePartial2D(from, to, inlier_flags, cv::RANSAC, options.ransac_threshold_px,
                                    static_cast<std::size_t>(options.ransac_iterations), 0.99, 10);
    if (!warp.empty()) {
      const int inliers = cv::countNonZero(inlier_flags);
      const double scale = std::hypot(warp.at<double>(0, 0), warp.at<double>(1, 0));
      bool plausible_scale =
          scale <= options.max_scale_change && scale * options.max_scale_change >= 1.0;
      if (fallback.motion == InstanceMotion::kPredicted &&
          options.max_scale_change_from_prediction > 0.0) {
        const double ratio = scale / std::max(1e-6, warpScale(fallback.warp));
        plausible_scale = plausible_scale && ratio <= options.max_scale_change_from_prediction &&
                          ratio * options.max_scale_change_from_prediction >= 1.0;
      }
      if (plausible_scale && inliers >= 3 &&
          inliers >= options.min_inlier_ratio * static_cast<double>(from.size())) {
        fit.motion = InstanceMotion::kSimilarity;
        fit.warp = cv::Matx23d(warp.ptr<double>());
        fit.inliers = inliers;
        return fit;
      }
    }
  }
  std::vector<double> dx, dy;
  dx.reserve(from.size());
  dy.reserve(from.size());
  for (std::size_t i = 0; i < from.size(); ++i) {
    dx.push_back(to[i].x - from[i].x);
    dy.push_back(to[i].y - from[i].y);
  }
  const double tx = median(dx), ty = median(dy);
  // The translation must rest on enough matches that agree with it: one or two stray matches
  // (a person walking behind something) would otherwise throw the mask across the image.
  const double tolerance = options.translation_agreement_px;
  int agreeing = 0;
  for (std::size_t i = 0; i < dx.size(); ++i) {
    agreeing += std::hypot(dx[i] - tx, dy[i] - ty) <= tolerance ? 1 : 0;
  }
  if (agreeing < options.min_matches_for_translation ||
      agreeing < options.min_inlier_ratio * static_cast<double>(dx.size())) {
    return fit;
  }
  fit.motion = InstanceMotion::kTranslation;
  fit.warp = translation(tx, ty);
  fit.inliers = agreeing;
  return fit;
}

// How far an instance cut by the keyframe's image edge grows back out past that edge: as far as
// the warp brings the edge into the frame (in keyframe pixels), on each side it touches.
struct EdgeGrowth {
  int left = 0, top = 0, right = 0, bottom = 0;
  bool any() const { return left + top + right + bottom > 0; }
};

EdgeGrowth growthPastCutEdges(const cv::Rect& box, const cv::Size& image, const cv::Matx23d& warp) {
  EdgeGrowth growth;
  const double scale = std::max(1e-3, warpScale(warp));
  // Never more than the image: a wild warp must not paint a runaway strip.
  const auto pixels = [&](double inward, int limit) {
    return inward <= 0.0 ? 0 : std::min(limit, static_cast<int>(std::ceil(inward / scale)));
  };
  // A mask resampled from the edge's reduced resolution may stop a pixel or two short of the edge.
  constexpr int kCutTolerancePx = 2;
  const double top = box.y, bottom = box.br().y, left = box.x, right = box.br().x;
  if (box.x <= kCutTolerancePx) {
    growth.left = pixels(
        std::min(warpPoint(warp, {left, top}).x, warpPoint(warp, {left, bottom}).x), image.width);
  }
  if (box.br().x >= image.width - kCutTolerancePx) {
    const double w = image.width;
    growth.right =
        pixels(w - std::max(warpPoint(warp, {right, top}).x, warpPoint(warp, {right, bottom}).x),
               image.width);
  }
  if (box.y <= kCutTolerancePx) {
    growth.top = pixels(std::min(warpPoint(warp, {left, top}).y, warpPoint(warp, {right, top}).y),
                        image.height);
  }
  if (box.br().y >= image.height - kCutTolerancePx) {
    const double h = image.height;
    growth.bottom =
        pixels(h - std::max(warpPoint(warp, {left, bottom}).y, warpPoint(warp, {right, bottom}).y),
               image.height);
  }
  return growth;
}

// Paints the pixels of `label` inside `source_box` of `source`, moved by `warp`, into `target`.
// With `grow_cut_edges`, an instance cut by the image edge that the warp moves inwards has its
// pixels on the cut repeated outwards first: the part of a person that was out of the keyframe's
// view comes in with them (someone walking in from the side is masked whole, not as the sliver
// the keyframe saw).
void paintWarped(const cv::Mat1b& source, std::uint8_t label, const cv::Rect& source_box,
                 const cv::Matx23d& warp, bool grow_cut_edges, cv::Mat1b& target) {
  cv::Mat1b instance = source(source_box) == label;
  cv::Rect box = source_box;
  if (grow_cut_edges) {
    const EdgeGrowth g = growthPastCutEdges(source_box, source.size(), warp);
    if (g.any()) {
      cv::copyMakeBorder(instance, instance, g.top, g.bottom, g.left, g.right,
                         cv::BORDER_REPLICATE);
      box = cv::Rect(box.x - g.left, box.y - g.top, box.width + g.left + g.right,
                     box.height + g.top + g.bottom);
    }
  }
  std::array<cv::Point2f, 4> corners;
  const std::array<cv::Point2d, 4> box_corners = {
      cv::Point2d(box.x, box.y), cv::Point2d(box.br().x, box.y), cv::Point2d(box.x, box.br().y),
      cv::Point2d(box.br().x, box.br().y)};
  for (std::size_t i = 0; i < 4; ++i) {
    const cv::Point2d c = warpPoint(warp, box_corners[i]);
    corners[i] = cv::Point2f(static_cast<float>(c.x), static_cast<float>(c.y));
  }
  const cv::Rect target_box =
      cv::boundingRect(std::vector<cv::Point2f>(corners.begin(), corners.end())) &
      cv::Rect(0, 0, target.cols, target.rows);
  if (target_box.empty()) return;
  // Maps box pixels to target-box pixels: shift into the image, warp, shift into the box.
  const cv::Matx23d local(
      warp(0, 0), warp(0, 1), warp(0, 0) * box.x + warp(0, 1) * box.y + warp(0, 2) - target_box.x,
      warp(1, 0), warp(1, 1), warp(1, 0) * box.x + warp(1, 1) * box.y + warp(1, 2) - target_box.y);
  cv::Mat1b moved;
  cv::warpAffine(instance, moved, local, target_box.size(), cv::INTER_NEAREST, cv::BORDER_CONSTANT,
                 cv::Scalar(0));
  target(target_box).setTo(label, moved);
}

}  // namespace

const char* toString(InstanceMotion motion) {
  switch (motion) {
    case InstanceMotion::kSimilarity:
      return "similarity";
    case InstanceMotion::kTranslation:
      return "translation";
    case InstanceMotion::kBackground:
      return "background";
    case InstanceMotion::kPredicted:
      return "predicted";
    case InstanceMotion::kIdentity:
      return "identity";
  }
  return "?";
}

PreparedLabels prepareLabels(cv::Mat1b labels, int near_margin_px) {
  if (labels.empty()) throw std::invalid_argument("mask transfer of an empty label image");
  PreparedLabels prepared;
  prepared.labels = std::move(labels);
  const std::array<InstanceExtent, kLabels> extents = instanceExtents(prepared.labels);
  for (std::size_t label = 1; label < extents.size(); ++label) {
    if (!extents[label].present()) continue;
    prepared.boxes[label] = extents[label].rect();
    prepared.any = true;
  }
  prepared.near_margin_px = std::max(0, near_margin_px);
  if (prepared.any && prepared.near_margin_px > 0) {
    // Grey dilation spreads each label over its neighbourhood (where two meet, the larger wins).
    const int side = 2 * prepared.near_margin_px + 1;
    cv::dilate(prepared.labels, prepared.labels_near,
               cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
  } else {
    prepared.labels_near = prepared.labels;
  }
  return prepared;
}

MaskTransferResult transferLabels(const cv::Mat1b& keyframe_labels,
                                  const std::vector<cv::Point2f>& keyframe_points,
                                  const std::vector<cv::Point2f>& current_points,
                                  const MaskTransferOptions& options) {
  if (keyframe_points.size() != current_points.size()) {
    throw std::invalid_argument("mask transfer needs matched point lists of equal length, got " +
                                std::to_string(keyframe_points.size()) + " and " +
                                std::to_string(current_points.size()));
  }
  return transferLabels(prepareLabels(keyframe_labels, options.near_margin_px), keyframe_points,
                        current_points, options);
}

MaskTransferResult transferLabels(const PreparedLabels& prepared,
                                  const std::vector<cv::Point2f>& keyframe_points,
                                  const std::vector<cv::Point2f>& current_points,
                                  const MaskTransferOptions& options,
                                  const PredictedWarps* predicted) {
  const cv::Mat1b& keyframe_labels = prepared.labels;
  if (keyframe_points.size() != current_points.size()) {
    throw std::invalid_argument("mask transfer needs matched point lists of equal length, got " +
                                std::to_string(keyframe_points.size()) + " and " +
                                std::to_string(current_points.size()));
  }
  if (keyframe_labels.empty()) throw std::invalid_argument("mask transfer of an empty label image");
  if (prepared.near_margin_px != std::max(0, options.near_margin_px)) {
    throw std::invalid_argument("labels prepared for another near margin");
  }
  MaskTransferResult result;
  result.labels = cv::Mat1b::zeros(keyframe_labels.size());
  result.mask = cv::Mat1b::zeros(keyframe_labels.size());
  if (!prepared.any) return result;

  std::array<std::vector<int>, kLabels> on_instance, near_instance;
  std::vector<int> background;
  const cv::Rect image(0, 0, keyframe_labels.cols, keyframe_labels.rows);
  for (std::size_t i = 0; i < keyframe_points.size(); ++i) {
    const int x = cvFloor(keyframe_points[i].x), y = cvFloor(keyframe_points[i].y);
    if (!image.contains(cv::Point(x, y))) continue;
    const std::uint8_t label = keyframe_labels(y, x);
    if (label != 0) {
      on_instance[label].push_back(static_cast<int>(i));
      continue;
    }
    background.push_back(static_cast<int>(i));
    const std::uint8_t near = prepared.labels_near(y, x);
    if (near != 0) near_instance[near].push_back(static_cast<int>(i));
  }

  auto gather = [&](const std::vector<int>& indices, std::vector<cv::Point2f>& from,
                    std::vector<cv::Point2f>& to) {
    for (int index : indices) {
      from.push_back(keyframe_points[static_cast<std::size_t>(index)]);
      to.push_back(current_points[static_cast<std::size_t>(index)]);
    }
  };
  std::vector<cv::Point2f> from, to;
  gather(background, from, to);
  TransferredInstance identity;
  result.background = fitMotion(from, to, options, identity);
  TransferredInstance background_fallback = result.background;
  if (background_fallback.motion != InstanceMotion::kIdentity) {
    background_fallback.motion = InstanceMotion::kBackground;
  }

  for (int label = kLabels - 1; label >= 1; --label) {  // label 1 (best score) painted last
    const cv::Rect& box = prepared.boxes[static_cast<std::size_t>(label)];
    if (box.empty()) continue;
    from.clear();
    to.clear();
    const auto& own = on_instance[static_cast<std::size_t>(label)];
    gather(own.empty() ? near_instance[static_cast<std::size_t>(label)] : own, from, to);
    TransferredInstance fallback = background_fallback;
    if (predicted != nullptr && (*predicted)[static_cast<std::size_t>(label)]) {
      fallback.motion = InstanceMotion::kPredicted;
      fallback.warp = *(*predicted)[static_cast<std::size_t>(label)];
    }
    TransferredInstance moved = fitMotion(from, to, options, fallback);
    moved.label = static_cast<std::uint8_t>(label);
    paintWarped(keyframe_labels, moved.label, box, moved.warp, options.grow_cut_edges,
                result.labels);
    result.instances.push_back(moved);
  }
  std::reverse(result.instances.begin(), result.instances.end());
  result.mask.setTo(255, result.labels);
  return result;
}

MaskTransferResult transferMask(const cv::Mat1b& keyframe_mask,
                                const std::vector<cv::Point2f>& keyframe_points,
                                const std::vector<cv::Point2f>& current_points,
                                const MaskTransferOptions& options) {
  if (keyframe_mask.empty()) throw std::invalid_argument("mask transfer of an empty mask");
  // Fragments closer than the gap (a person's mask split at the waist) form one instance.
  cv::Mat1b grouped;  // not a view of keyframe_mask: dilate would write into the caller's mask
  if (options.merge_gap_px <= 0) {
    grouped = keyframe_mask;
  } else {
    const int size = 2 * options.merge_gap_px + 1;
    cv::dilate(keyframe_mask, grouped,
               cv::getStructuringElement(cv::MORPH_RECT, cv::Size(size, size)));
  }
  cv::Mat1i components;
  cv::connectedComponents(grouped, components, 8, CV_32S);
  cv::Mat1b labels;
  components.convertTo(labels, CV_8U);  // saturates: components past 255 share label 255
  labels.setTo(0, keyframe_mask == 0);
  return transferLabels(labels, keyframe_points, current_points, options);
}

}  // namespace edgeslam
