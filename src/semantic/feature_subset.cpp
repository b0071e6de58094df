#include "semantic/feature_subset.h"

#include <stdexcept>
#include <string>

namespace edgeslam {

std::shared_ptr<FrameFeatures> selectFeatures(const FrameFeatures& all,
                                              const std::vector<int>& keep,
                                              const PinholeCamera& camera) {
  auto out = std::make_shared<FrameFeatures>();
  out->scales = all.scales;
  out->bf = all.bf;
  out->keypoints.reserve(keep.size());
  out->descriptors.create(static_cast<int>(keep.size()), all.descriptors.cols,
                          all.descriptors.type());
  const bool with_depth = !all.depth.empty();
  if (with_depth) {
    out->depth.reserve(keep.size());
    out->right_u.reserve(keep.size());
  }
  for (std::size_t k = 0; k < keep.size(); ++k) {
    const int i = keep[k];
    if (i < 0 || static_cast<std::size_t>(i) >= all.size()) {
      throw std::out_of_range("feature index " + std::to_string(i) + " outside 0.." +
                              std::to_string(all.size()));
    }
    out->keypoints.push_back(all.keypoints[i]);
    all.descriptors.row(i).copyTo(out->descriptors.row(static_cast<int>(k)));
    if (with_depth) {
      out->depth.push_back(all.depth[i]);
      out->right_u.push_back(all.right_u.empty() ? -1.f : all.right_u[i]);
    }
  }
  out->grid = FeatureGrid(camera.undistortedBounds(), out->keypoints);
  return out;
}

}  // namespace edgeslam
