#pragma once
// Scores of a predicted (transferred / segmented) people mask against the ground truth of a
// generated dynamic sequence, and of the features that tracking kept.
#include <cstddef>
#include <opencv2/core.hpp>
#include <optional>
#include <vector>

namespace edgeslam {

// Intersection over union of the non-zero pixels; nullopt when both masks are empty (nothing to
// score). Throws std::invalid_argument when the sizes differ.
std::optional<double> maskIoU(const cv::Mat1b& predicted, const cv::Mat1b& truth);

struct FeaturesOnMask {
  std::size_t total = 0;    // points inside the image
  std::size_t on_mask = 0;  // of those, on a non-zero mask pixel
  // Share of the points on the mask; nullopt without points.
  std::optional<double> share() const {
    if (total == 0) return std::nullopt;
    return static_cast<double>(on_mask) / static_cast<double>(total);
  }
};

// Counts the points (pixel coordinates, rounded) that fall on the mask, e.g. the features kept
// for tracking on a frame: a good dynamic-object filter keeps few on people.
FeaturesOnMask countFeaturesOnMask(const std::vector<cv::Point2f>& points, const cv::Mat1b& mask);

}  // namespace edgeslam
