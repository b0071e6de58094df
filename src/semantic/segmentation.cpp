#include "semantic/segmentation.h"

#include <algorithm>

namespace edgeslam {

Segmentation assembleSegmentation(std::vector<SegmentedInstance> instances, cv::Size size) {
  std::stable_sort(
      instances.begin(), instances.end(),
      [](const SegmentedInstance& a, const SegmentedInstance& b) { return a.score > b.score; });
  Segmentation out;
  out.movable_mask = cv::Mat1b::zeros(size);
  out.label_image = cv::Mat1b::zeros(size);
  // Paint box-only masks first, then pixel masks, each lowest score first: a person in front of a
  // bus keeps their own pixels, and among equals the higher score ends up on top.
  for (const bool pixel_masks : {false, true}) {
    for (std::size_t i = instances.size(); i-- > 0;) {
      const SegmentedInstance& instance = instances[i];
      if (instance.mask.size() != size || instance.mask_is_box == pixel_masks) continue;
      out.label_image.setTo(instanceLabel(i), instance.mask);
      out.movable_mask.setTo(255, instance.mask);
    }
  }
  out.instances = std::move(instances);
  return out;
}

}  // namespace edgeslam
