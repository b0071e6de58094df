#pragma once
// Point queries against a mask, and dropping the features that fall on masked (movable) objects.
#include <opencv2/core.hpp>
#include <vector>

namespace edgeslam {

// True when a non-zero mask pixel lies within `margin_px` (Chebyshev distance) of `point`.
// Points outside the image are tested against the part of the window inside it.
bool insideMask(const cv::Mat1b& mask, cv::Point2f point, int margin_px = 0);

// Indices of the points that lie outside `mask` dilated by `margin_px`: the features to keep for
// tracking and for new map points. An empty mask keeps every point.
std::vector<int> indicesOutsideMask(const std::vector<cv::Point2f>& points, const cv::Mat1b& mask,
                                    int margin_px);
std::vector<int> indicesOutsideMask(const std::vector<cv::KeyPoint>& keypoints,
                                    const cv::Mat1b& mask, int margin_px);

}  // namespace edgeslam
