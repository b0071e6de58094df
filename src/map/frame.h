#pragma once
// A frame being tracked: its features, its estimated pose and which map point each keypoint
// matched.
#include <memory>
#include <optional>
#include <vector>

#include "features/frame_features.h"
#include "geometry/camera.h"
#include "geometry/se3.h"

namespace edgeslam {

class MapPoint;
class KeyFrame;

struct Frame {
  Frame() = default;
  Frame(std::size_t frame_index, double frame_timestamp,
        std::shared_ptr<const FrameFeatures> frame_features, const PinholeCamera* frame_camera)
      : index(frame_index),
        timestamp(frame_timestamp),
        features(std::move(frame_features)),
        camera(frame_camera),
        points(features->size(), nullptr),
        outliers(features->size(), false) {}

  std::size_t index = 0;
  double timestamp = 0.0;
  std::shared_ptr<const FrameFeatures> features;
  const PinholeCamera* camera = nullptr;
  std::optional<SE3d> T_cw;  // camera-from-world once estimated
  std::vector<MapPoint*> points;
  std::vector<bool> outliers;
  KeyFrame* reference_keyframe = nullptr;

  std::size_t size() const { return points.size(); }
  Eigen::Vector3d cameraCenter() const { return T_cw->inverse().translation(); }
  int matchedCount() const {
    int n = 0;
    for (std::size_t i = 0; i < points.size(); ++i) n += (points[i] != nullptr && !outliers[i]);
    return n;
  }
};

}  // namespace edgeslam
