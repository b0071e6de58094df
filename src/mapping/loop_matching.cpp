#include "mapping/loop_matching.h"

#include <algorithm>
#include <climits>
#include <stdexcept>
#include <string>
#include <unordered_set>

#include "features/descriptor_distance.h"

namespace edgeslam {
namespace {

constexpr double kMaxViewCos = 0.5;  // 60 degrees from the point's mean viewing direction

void requireSlots(const KeyFrame& keyframe, const std::vector<MapPoint*>& slots, const char* who) {
  if (slots.size() != keyframe.size()) {
    throw std::invalid_argument(std::string(who) + ": " + std::to_string(slots.size()) +
                                " match slots for keyframe " + std::to_string(keyframe.id()) +
                                " with " + std::to_string(keyframe.size()) + " keypoints");
  }
}

}  // namespace

std::vector<int> searchProjectedPoints(const KeyFrame& keyframe, const SE3d& T_cw,
                                       const PinholeCamera& camera,
                                       const std::vector<MapPoint*>& points, float radius,
                                       int max_distance, const std::vector<char>& eligible) {
  const FrameFeatures& f = keyframe.features();
  if (!eligible.empty() && eligible.size() != f.size()) {
    throw std::invalid_argument("searchProjectedPoints: eligibility flags do not match keyframe " +
                                std::to_string(keyframe.id()));
  }
  const Eigen::Matrix3d R = T_cw.rotationMatrix();
  const Eigen::Vector3d t = T_cw.translation();
  const Eigen::Vector3d centre = T_cw.inverse().translation();
  const PinholeCamera::Bounds bounds = camera.undistortedBounds();
  const int levels = f.scales.numLevels();
  const float scale_factor = static_cast<float>(f.scales.scaleFactor());

  std::vector<int> best_of(points.size(), -1);
  std::vector<int> area;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const MapPoint* p = points[k];
    if (p == nullptr || p->isBad()) continue;
    const Eigen::Vector3d pc = R * p->position() + t;
    if (!(pc.z() > 0.0)) continue;
    const double u = camera.fx() * pc.x() / pc.z() + camera.cx();
    const double v = camera.fy() * pc.y() / pc.z() + camera.cy();
    if (!(u >= bounds.min_x && u < bounds.max_x && v >= bounds.min_y && v < bounds.max_y)) continue;
    const Eigen::Vector3d ray = p->position() - centre;
    const double distance = ray.norm();
    if (distance < p->minDistance() || distance > p->maxDistance()) continue;
    if (ray.dot(p->normal()) < kMaxViewCos * distance) continue;

    const int level = p->predictLevel(static_cast<float>(distance), scale_factor, levels);
    const float window = radius * static_cast<float>(f.scales.scale(level));
    f.grid.featuresInArea(static_cast<float>(u), static_cast<float>(v), window,
                          std::max(0, level - 1), std::min(levels - 1, level + 1), area);
    const cv::Mat& descriptor = p->descriptor();
    if (descriptor.empty()) continue;
    int best = -1;
    int best_distance = INT_MAX;
    for (const int i : area) {
      if (!eligible.empty() && !eligible[static_cast<std::size_t>(i)]) continue;
      const int d =
          descriptorDistance(descriptor.ptr<std::uint8_t>(0), f.descriptors.ptr<std::uint8_t>(i));
      if (d < best_distance) {
        best_distance = d;
        best = i;
      }
    }
    if (best >= 0 && best_distance <= max_distance) best_of[k] = best;
  }
  return best_of;
}

int searchBySim3(const KeyFrame& kf1, const KeyFrame& kf2, const Sim3d& S_12,
                 const PinholeCamera& camera, std::vector<MapPoint*>& matches12, float radius,
                 int max_distance) {
  requireSlots(kf1, matches12, "searchBySim3");
  std::unordered_set<const MapPoint*> already(matches12.begin(), matches12.end());
  // kf2's unmatched points into kf1, kf1's unmatched points into kf2.
  std::vector<MapPoint*> points2(kf2.size(), nullptr);
  for (std::size_t j = 0; j < kf2.size(); ++j) {
    MapPoint* p = kf2.point(j);
    if (p != nullptr && !p->isBad() && !already.contains(p)) points2[j] = p;
  }
  std::vector<MapPoint*> points1(kf1.size(), nullptr);
  std::vector<char> free1(kf1.size(), 0);
  for (std::size_t i = 0; i < kf1.size(); ++i) {
    MapPoint* p = kf1.point(i);
    if (p != nullptr && !p->isBad() && matches12[i] == nullptr) {
      points1[i] = p;
      free1[i] = 1;
    }
  }
  std::vector<char> free2(kf2.size(), 0);
  for (std::size_t j = 0; j < kf2.size(); ++j) free2[j] = points2[j] != nullptr;

  const SE3d T_1w = (S_12 * Sim3d(kf2.pose())).toSE3();            // kf2's points into kf1
  const SE3d T_2w = (S_12.inverse() * Sim3d(kf1.pose())).toSE3();  // kf1's points into kf2
  const std::vector<int> in1 =
      searchProjectedPoints(kf1, T_1w, camera, points2, radius, max_distance, free1);
  const std::vector<int> in2 =
      searchProjectedPoints(kf2, T_2w, camera, points1, radius, max_distance, free2);
  int added = 0;
  for (std::size_t j = 0; j < in1.size(); ++j) {
    const int i = in1[j];
    if (i < 0 || in2[static_cast<std::size_t>(i)] != static_cast<int>(j)) continue;
    if (matches12[static_cast<std::size_t>(i)] != nullptr) continue;
    matches12[static_cast<std::size_t>(i)] = points2[j];
    ++added;
  }
  return added;
}

int searchByProjectionSim3(const KeyFrame& keyframe, const Sim3d& S_cw, const PinholeCamera& camera,
                           const std::vector<MapPoint*>& points, std::vector<MapPoint*>& matched,
                           float radius, int max_distance) {
  requireSlots(keyframe, matched, "searchByProjectionSim3");
  std::unordered_set<const MapPoint*> already(matched.begin(), matched.end());
  std::vector<MapPoint*> unmatched;
  unmatched.reserve(points.size());
  for (MapPoint* p : points) {
    if (p != nullptr && !p->isBad() && !already.contains(p)) unmatched.push_back(p);
  }
  std::vector<char> free(matched.size(), 0);
  for (std::size_t i = 0; i < matched.size(); ++i) free[i] = matched[i] == nullptr;
  const std::vector<int> best =
      searchProjectedPoints(keyframe, S_cw.toSE3(), camera, unmatched, radius, max_distance, free);
  int added = 0;
  for (std::size_t k = 0; k < unmatched.size(); ++k) {
    const int i = best[k];
    if (i < 0 || matched[static_cast<std::size_t>(i)] != nullptr) continue;
    matched[static_cast<std::size_t>(i)] = unmatched[k];
    ++added;
  }
  return added;
}

}  // namespace edgeslam
