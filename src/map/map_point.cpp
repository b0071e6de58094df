#include "map/map_point.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "features/descriptor_distance.h"
#include "map/keyframe.h"

namespace edgeslam {

MapPoint::MapPoint(MapPointId id, const Eigen::Vector3d& position, KeyFrame* reference_keyframe)
    : id_(id),
      position_(position),
      reference_keyframe_(reference_keyframe),
      first_keyframe_id_(reference_keyframe != nullptr ? reference_keyframe->id() : kInvalidId) {}

int MapPoint::predictLevel(float distance, float scale_factor, int levels) const {
  if (distance <= 0.f || max_distance_ <= 0.f) return 0;
  const float ratio = max_distance_ / distance;
  const int level = static_cast<int>(std::ceil(std::log(ratio) / std::log(scale_factor)));
  return std::clamp(level, 0, levels - 1);
}

void MapPoint::updateNormalAndDepth() {
  if (observations_.empty() || reference_keyframe_ == nullptr) return;
  Eigen::Vector3d normal_sum = Eigen::Vector3d::Zero();
  for (const auto& [id, obs] : observations_) {
    const Eigen::Vector3d ray = position_ - obs.keyframe->cameraCenter();
    const double n = ray.norm();
    if (n > 0) normal_sum += ray / n;
  }
  const double norm = normal_sum.norm();
  if (norm > 0) normal_ = normal_sum / norm;

  const auto ref = observations_.find(reference_keyframe_->id());
  if (ref == observations_.end()) return;
  const FrameFeatures& features = reference_keyframe_->features();
  const int level = features.keypoints[ref->second.index].octave;
  const float distance =
      static_cast<float>((position_ - reference_keyframe_->cameraCenter()).norm());
  max_distance_ = distance * static_cast<float>(features.scales.scale(level));
  min_distance_ =
      max_distance_ / static_cast<float>(features.scales.scale(features.scales.numLevels() - 1));
}

void MapPoint::computeDistinctiveDescriptor() {
  // The representative descriptor is the observed one with the least median distance to the others.
  std::vector<const std::uint8_t*> descriptors;
  descriptors.reserve(observations_.size());
  for (const auto& [id, obs] : observations_) {
    if (obs.keyframe->isBad()) continue;
    descriptors.push_back(
        obs.keyframe->features().descriptors.ptr<std::uint8_t>(static_cast<int>(obs.index)));
  }
  if (descriptors.empty()) return;
  const std::size_t n = descriptors.size();
  std::vector<int> distances(n * n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i + 1; j < n; ++j) {
      const int d = descriptorDistance(descriptors[i], descriptors[j]);
      distances[i * n + j] = d;
      distances[j * n + i] = d;
    }
  }
  std::size_t best = 0;
  int best_median = kDescriptorBits + 1;
  std::vector<int> row(n);
  for (std::size_t i = 0; i < n; ++i) {
    std::copy(distances.begin() + static_cast<long>(i * n),
              distances.begin() + static_cast<long>((i + 1) * n), row.begin());
    std::nth_element(row.begin(), row.begin() + static_cast<long>((n - 1) / 2), row.end());
    const int median = row[(n - 1) / 2];
    if (median < best_median) {
      best_median = median;
      best = i;
    }
  }
  descriptor_ = cv::Mat(1, kDescriptorBytes, CV_8UC1);
  std::memcpy(descriptor_.data, descriptors[best], kDescriptorBytes);
}

}  // namespace edgeslam
