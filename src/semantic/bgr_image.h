#pragma once
#include <opencv2/core.hpp>

namespace edgeslam {

// An 8-bit BGR view or copy of an 8-bit grey, BGR or BGRA image; throws std::invalid_argument for
// an empty image or another type.
cv::Mat toBgr8(const cv::Mat& image);

}  // namespace edgeslam
