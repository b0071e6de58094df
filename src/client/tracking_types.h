#pragma once
// Shared vocabulary of the tracker and whoever consumes its keyframes.
#include <cstddef>
#include <opencv2/core/types.hpp>
#include <optional>
#include <vector>

#include "geometry/se3.h"
#include "map/ids.h"
#include "map/keyframe_sink.h"
#include "map/sensor.h"

namespace edgeslam {

enum class TrackingState { kNotInitialized, kOk, kLost };

const char* toString(TrackingState state);

struct TrackResult {
  TrackingState state = TrackingState::kNotInitialized;
  std::optional<SE3d> T_cw;  // camera-from-world when tracked
  bool new_keyframe = false;
  KeyFrameId keyframe = kInvalidId;  // the new keyframe's id
  bool relocalized = false;
  int tracked_points = 0;
  // With TrackerOptions::report_feature_positions (for a viewer): the frame's features in pixels,
  // those tracking matched to a map point and the rest (new: no point yet). Features culled
  // before tracking (semantic culling) are in neither.
  std::vector<cv::Point2f> features_on_map;
  std::vector<cv::Point2f> features_new;
};

}  // namespace edgeslam
