#pragma once
// The result of segmenting one image: instances of movable classes, their union, and a label image.
#include <algorithm>
#include <cstdint>
#include <opencv2/core.hpp>
#include <string>
#include <vector>

namespace edgeslam {

struct SegmentedInstance {
  int class_id = -1;  // COCO id (0 = person)
  std::string class_name;
  float score = 0.0f;
  cv::Rect box;             // in image pixels, clipped to the image
  cv::Mat1b mask;           // full image size, 255 inside the instance
  bool mask_is_box = true;  // true when the mask is the whole box (no pixel-level mask)
};

struct Segmentation {
  std::vector<SegmentedInstance> instances;  // highest score first
  cv::Mat1b movable_mask;  // union of the instance masks, full image size, 255 inside
  cv::Mat1b label_image;   // 0 background, i + 1 = instance i (instances past 254 share 255)
  double elapsed_ms = 0.0;
};

constexpr int kMaxLabel = 255;

// Label of instance `index` in a label image (index + 1, capped at kMaxLabel).
inline std::uint8_t instanceLabel(std::size_t index) {
  return static_cast<std::uint8_t>(std::min<std::size_t>(index + 1, kMaxLabel));
}

// Sorts the instances by score (highest first) and fills movable_mask and label_image for an image
// of `size`. Where instances overlap, pixel-level masks own the pixel over box-only masks, then the
// higher score wins.
Segmentation assembleSegmentation(std::vector<SegmentedInstance> instances, cv::Size size);

}  // namespace edgeslam
