#pragma once
// Pastes people sprites over a real frame: alpha blending with a slightly feathered edge, a
// ground-truth mask (alpha > 0.5) and, for RGB-D, the people's depth written into the frame's
// depth so that they are a real foreground object.
#include <opencv2/core.hpp>
#include <vector>

#include "synth/people_motion.h"
#include "synth/person_sprite.h"

namespace edgeslam {

struct CompositeOptions {
  double feather_sigma_px = 0.8;  // Gaussian blur of the silhouette edge
  // A person's depth is its nominal distance, moved forward where needed so that it is never
  // behind the real surface it covers: at most the 10th percentile of the covered depths minus
  // `clearance_m`, and per pixel at most the real depth minus `pixel_clearance_m`.
  double clearance_m = 0.1;
  double pixel_clearance_m = 0.02;
  double min_depth_m = 0.2;
};

struct CompositeFrame {
  cv::Mat image;          // same type as the input (CV_8UC3 or CV_8UC1); empty when none was given
  cv::Mat1b mask;         // 255 where the pasted people's alpha > 0.5
  cv::Mat1f depth_m;      // the input depth with the people's pixels replaced; empty without depth
  cv::Mat1f alpha;        // combined alpha of all people
  double coverage = 0.0;  // share of the image in `mask`
};

// `image` (8-bit BGR or grey, may be empty to get only mask and coverage) of size
// `layout_size`; `depth_m` (CV_32F metres, 0 = invalid) may be empty. `placements` are drawn in
// order (farthest first), so nearer people cover farther ones.
CompositeFrame compositePeople(const cv::Mat& image, const cv::Mat& depth_m, cv::Size image_size,
                               const std::vector<PersonPlacement>& placements,
                               const std::vector<PersonSprite>& sprites,
                               const CompositeOptions& options = {});

}  // namespace edgeslam
