// Reference-keyframe tracking without a pose: keyframe points against frame features by descriptor.
#include <climits>
#include <vector>

#include "features/descriptor_distance.h"
#include "features/rotation_histogram.h"
#include "map/map_matching.h"
#include "map/map_matching_internal.h"

namespace edgeslam {

int matchKeyFrameByDescriptor(const KeyFrame& keyframe, Frame& frame, float ratio) {
  matching_detail::requireFeatures(frame, "matchKeyFrameByDescriptor");
  const FrameFeatures& features = *frame.features;
  const FrameFeatures& kf_features = keyframe.features();
  if (frame.size() == 0 || keyframe.size() == 0) return 0;

  // Each frame keypoint keeps the closest keyframe keypoint that chose it.
  std::vector<int> owner(frame.size(), -1);
  std::vector<int> owner_distance(frame.size(), INT_MAX);
  for (std::size_t i = 0; i < keyframe.size(); ++i) {
    if (!matching_detail::isUsable(keyframe.point(i))) continue;
    const BestTwo best = findBestTwo(kf_features.descriptors.ptr<std::uint8_t>(static_cast<int>(i)),
                                     features.descriptors);
    if (best.index < 0 || best.distance > kMatchDistanceLow || !best.passesRatio(ratio)) continue;
    const auto j = static_cast<std::size_t>(best.index);
    if (best.distance < owner_distance[j]) {
      owner[j] = static_cast<int>(i);
      owner_distance[j] = best.distance;
    }
  }

  // Rotation check before writing, so that rejected candidates never overwrite a frame slot.
  RotationHistogram histogram;
  for (std::size_t j = 0; j < frame.size(); ++j) {
    if (owner[j] >= 0) {
      histogram.add(kf_features.keypoints[static_cast<std::size_t>(owner[j])].angle,
                    features.keypoints[j].angle, static_cast<int>(j));
    }
  }
  int matches = 0;
  for (const int idx : histogram.consistent()) {
    const auto j = static_cast<std::size_t>(idx);
    frame.points[j] = keyframe.point(static_cast<std::size_t>(owner[j]));
    frame.outliers[j] = false;
    ++matches;
  }
  return matches;
}

}  // namespace edgeslam
