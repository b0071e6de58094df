#pragma once
#include <opencv2/core.hpp>

#include "semantic/segmentation.h"

namespace edgeslam {

// A copy of `bgr` with each instance's mask tinted in its own colour, its box drawn and labelled
// "class score".
cv::Mat drawSegmentation(const cv::Mat& bgr, const Segmentation& segmentation);

}  // namespace edgeslam
