#pragma once
// Helpers shared by the map matchers (not part of the public API): projection with a fixed pose,
// input checks, the one-match-per-keypoint bookkeeping and the rotation-consistency filter.
#include <Eigen/Core>
#include <algorithm>
#include <climits>
#include <vector>

#include "features/rotation_histogram.h"
#include "geometry/camera.h"
#include "geometry/se3.h"
#include "map/frame.h"
#include "map/map_point.h"

namespace edgeslam::matching_detail {

// Sets up once per call what every projection needs: R, t, intrinsics and image bounds.
class Projector {
 public:
  Projector(const SE3d& T_cw, const PinholeCamera& camera)
      : R_(T_cw.rotationMatrix()),
        t_(T_cw.translation()),
        fx_(camera.fx()),
        fy_(camera.fy()),
        cx_(camera.cx()),
        cy_(camera.cy()),
        bounds_(camera.undistortedBounds()) {}

  // Camera-frame point; false when it is not in front of the camera or lands outside the image.
  bool project(const Eigen::Vector3d& world, Eigen::Vector3d& camera_point, float& u,
               float& v) const {
    camera_point = R_ * world + t_;
    if (!(camera_point.z() > 0.0)) return false;
    const double inv_z = 1.0 / camera_point.z();
    const double pu = fx_ * camera_point.x() * inv_z + cx_;
    const double pv = fy_ * camera_point.y() * inv_z + cy_;
    if (!(pu >= bounds_.min_x && pu < bounds_.max_x && pv >= bounds_.min_y && pv < bounds_.max_y)) {
      return false;
    }
    u = static_cast<float>(pu);
    v = static_cast<float>(pv);
    return true;
  }

  double fx() const { return fx_; }

 private:
  Eigen::Matrix3d R_;
  Eigen::Vector3d t_;
  double fx_, fy_, cx_, cy_;
  PinholeCamera::Bounds bounds_;
};

// Throw std::invalid_argument naming `who` when the frame lacks features (or its points / outliers
// do not match them), its camera or its pose.
void requireFeatures(const Frame& frame, const char* who);
const PinholeCamera& requireCamera(const Frame& frame, const char* who);
const SE3d& requirePose(const Frame& frame, const char* who);

inline bool isUsable(const MapPoint* point) {
  return point != nullptr && !point->isBad();
}

// Sorted copy of the usable points of a list, for membership tests without hashing.
std::vector<const MapPoint*> sortedUsablePoints(const std::vector<MapPoint*>& points);
inline bool containsPoint(const std::vector<const MapPoint*>& sorted, const MapPoint* point) {
  return std::binary_search(sorted.begin(), sorted.end(), point);
}

// The best and second best distance among candidates, with the level of each (the local-map ratio
// test applies only between candidates on the same level).
struct BestTwoWithLevels {
  int index = -1;
  int distance = INT_MAX;
  int level = -1;
  int second_distance = INT_MAX;
  int second_level = -1;

  void consider(int candidate, int candidate_distance, int candidate_level) {
    if (candidate_distance < distance) {
      second_distance = distance;
      second_level = level;
      distance = candidate_distance;
      level = candidate_level;
      index = candidate;
    } else if (candidate_distance < second_distance) {
      second_distance = candidate_distance;
      second_level = candidate_level;
    }
  }
};

// Clears frame.points for the matches (ids = keypoint indices in `frame`) whose angle change falls
// outside the dominant rotation bins; returns how many were removed.
int removeRotationOutliers(const RotationHistogram& histogram, Frame& frame);

}  // namespace edgeslam::matching_detail
