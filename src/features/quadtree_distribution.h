#pragma once
// Spatially even selection of keypoints: the region is split quadtree-wise, always splitting the
// largest node first (ties: the node holding more keypoints), until there are as many non-empty
// nodes as wanted; each node then keeps its strongest keypoint (highest response).
#include <opencv2/core.hpp>
#include <vector>

namespace edgeslam {

// Returns at most `target` keypoints of `keypoints` (all of them when there are no more than
// `target`), in no particular order. `region` should enclose the keypoints; keypoints outside it
// are still kept in the nearest node. Roots are square-ish: round(width / height) of them side by
// side.
std::vector<cv::KeyPoint> distributeQuadtree(const std::vector<cv::KeyPoint>& keypoints,
                                             const cv::Rect2f& region, int target);

}  // namespace edgeslam
