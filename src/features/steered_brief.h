#pragma once
// Steered BRIEF: 256 intensity comparisons between point pairs of a fixed pattern, rotated by the
// keypoint's orientation (Rublee et al., "ORB", 2011). The pattern is generated, not learned: see
// steeredBriefPattern().
#include <array>
#include <opencv2/core.hpp>
#include <span>
#include <vector>

namespace edgeslam {

// Sample points of the pattern lie within this radius of the keypoint, before and after rotation,
// so a keypoint needs kBriefPatternRadius pixels of image on every side.
inline constexpr int kBriefPatternRadius = 15;

struct BriefPair {
  float x1, y1, x2, y2;
};

// The 256 test pairs. Generated once, deterministically, as in BRIEF's "G II" sampling: both points
// of a pair drawn independently from an isotropic Gaussian with sigma = patch size / 5 (patch size
// 31), redrawn when outside kBriefPatternRadius or when both points round to the same pixel. The
// random source is a fixed-seed SplitMix64 with Box-Muller, so the pattern is identical on every
// platform and compiler.
const std::array<BriefPair, 256>& steeredBriefPattern();

// Writes one 32-byte descriptor per keypoint into rows first_row.. of `descriptors` (CV_8UC1,
// 32 columns, already allocated). `smoothed` is the blurred level image; keypoint coordinates and
// angles (degrees) are in that level's pixels. Bit j of byte k is the test of pair 8k + j:
// 1 when the first point is darker than the second. Throws std::invalid_argument when a keypoint
// is closer than kBriefPatternRadius to the image border.
void computeSteeredBrief(const cv::Mat& smoothed, std::span<const cv::KeyPoint> keypoints,
                         cv::Mat& descriptors, int first_row);

}  // namespace edgeslam
