#pragma once
// Moving a whole map after an optimisation that changed some keyframes' poses: every other
// keyframe follows its nearest corrected ancestor in the spanning tree (it may have been created
// while the optimisation ran), and every point follows the keyframe that anchors it, keeping its
// coordinates in that camera (up to the similarity's scale). Callers hold the map's update mutex.
#include <Eigen/Core>
#include <unordered_map>

#include "geometry/sim3.h"
#include "map/keyframe.h"
#include "map/map.h"

namespace edgeslam {

struct KeyFrameCorrection {
  Sim3d before;  // camera-from-world the map's points are consistent with now
  Sim3d after;   // camera-from-world wanted
};

struct MapCorrection {
  std::unordered_map<KeyFrame*, KeyFrameCorrection> keyframes;
  // Points anchored to another keyframe than their reference keyframe (already moved with it).
  std::unordered_map<MapPoint*, KeyFrame*> point_anchor;
  // Points whose new position is known outright (bundle adjustment).
  std::unordered_map<MapPoint*, Eigen::Vector3d> point_positions;
};

struct MapCorrectionStats {
  std::size_t keyframes_moved = 0;
  std::size_t keyframes_propagated = 0;  // not in the correction: followed an ancestor
  std::size_t points_moved = 0;
};

// The world-to-world similarity a keyframe's correction implies: after^-1 * before.
Sim3d worldCorrection(const KeyFrameCorrection& correction);

MapCorrectionStats applyMapCorrection(Map& map, const MapCorrection& correction)
    REQUIRES(map.updateMutex());

}  // namespace edgeslam
