#pragma once
// Guided matching for loop closing: map points projected into a keyframe under a similarity, which
// map_matching.h (rigid poses of one map) does not cover. A Sim(3) camera-from-world S projects a
// point exactly as its rigid part S.toSE3() does, and that rigid pose measures distances in the
// points' own units, so the searches below take S.toSE3(). Callers hold the map's update mutex.
#include <vector>

#include "geometry/camera.h"
#include "geometry/se3.h"
#include "geometry/sim3.h"
#include "map/keyframe.h"
#include "map/map_point.h"

namespace edgeslam {

// For each point (nullptr and bad points skipped): projects it into `keyframe` with `T_cw`; when it
// lands in the image, in front, within the point's distance range and seen within 60 degrees of its
// normal, searches a window of `radius` * scale(predicted level) at levels predicted -1..+1 for the
// closest keypoint with Hamming <= max_distance. `eligible` (one flag per keypoint, or empty for
// all) limits the keypoints considered. Returns, per point, the keypoint index or -1.
std::vector<int> searchProjectedPoints(const KeyFrame& keyframe, const SE3d& T_cw,
                                       const PinholeCamera& camera,
                                       const std::vector<MapPoint*>& points, float radius,
                                       int max_distance, const std::vector<char>& eligible = {});

// Mutual guided matching between two keyframes under S_12 (camera 1 from camera 2): kf2's points
// projected into kf1 and kf1's points into kf2; a pair is kept when each is the other's best.
// Only keypoints with a point and without an entry in `matches12` (one per kf1 keypoint: kf2's
// point, or nullptr) take part; new pairs are written there. Returns how many were added.
int searchBySim3(const KeyFrame& kf1, const KeyFrame& kf2, const Sim3d& S_12,
                 const PinholeCamera& camera, std::vector<MapPoint*>& matches12, float radius,
                 int max_distance);

// Projects `points` into `keyframe` under the similarity S_cw and records the closest keypoint for
// each point not yet in `matched` (one entry per keypoint of `keyframe`), at keypoints whose entry
// is still nullptr. Returns how many were added.
int searchByProjectionSim3(const KeyFrame& keyframe, const Sim3d& S_cw, const PinholeCamera& camera,
                           const std::vector<MapPoint*>& points, std::vector<MapPoint*>& matched,
                           float radius, int max_distance);

}  // namespace edgeslam
