#pragma once
// FAST corners with a per-cell adaptive threshold: the whole region is searched with the high
// threshold, and cells of the grid where nothing was found are searched again with the low one,
// so that weakly textured areas still get corners.
#include <opencv2/core.hpp>
#include <vector>

namespace edgeslam {

struct FastGridOptions {
  int high_threshold = 20;
  int low_threshold = 7;
  int cell_size = 30;  // pixels; cells are stretched evenly to tile the region
};

// Appends to `keypoints` the FAST-9 corners (non-maximum suppressed, response = FAST score) whose
// pixel lies inside `region` of `image` (CV_8UC1). The region must keep 3 pixels from the image
// border (FAST's circle); throws std::invalid_argument otherwise.
void detectFastInGrid(const cv::Mat& image, const cv::Rect& region, const FastGridOptions& options,
                      std::vector<cv::KeyPoint>& keypoints);

}  // namespace edgeslam
