#include "mapping/loop_map_correction.h"

#include <algorithm>
#include <unordered_set>
#include <vector>

namespace edgeslam {
namespace {

bool isIdentity(const Sim3d& s) {
  return s.scale() == 1.0 && s.translation().isZero(0.0) &&
         s.rotation().coeffs() == Eigen::Quaterniond::Identity().coeffs();
}

}  // namespace

Sim3d worldCorrection(const KeyFrameCorrection& correction) {
  return correction.after.inverse() * correction.before;
}

MapCorrectionStats applyMapCorrection(Map& map, const MapCorrection& correction) {
  MapCorrectionStats stats;
  // Each keyframe's world correction, computed before anything moves.
  std::unordered_map<const KeyFrame*, Sim3d> world_of;
  for (const auto& [kf, c] : correction.keyframes) world_of.emplace(kf, worldCorrection(c));
  const auto worldFor = [&](KeyFrame* kf) -> Sim3d {
    std::vector<KeyFrame*> chain;
    Sim3d found = Sim3d::identity();
    for (KeyFrame* k = kf; k != nullptr; k = k->parent()) {
      if (const auto it = world_of.find(k); it != world_of.end()) {
        found = it->second;
        break;
      }
      chain.push_back(k);
      if (chain.size() > 1'000'000) break;  // a cycle would be a bug elsewhere; do not hang
    }
    for (KeyFrame* k : chain) world_of.emplace(k, found);
    return found;
  };

  const std::vector<KeyFrame*> keyframes = map.keyFrames();
  std::vector<std::pair<KeyFrame*, SE3d>> new_poses;
  new_poses.reserve(keyframes.size());
  for (KeyFrame* kf : keyframes) {
    if (const auto it = correction.keyframes.find(kf); it != correction.keyframes.end()) {
      new_poses.emplace_back(kf, it->second.after.toSE3());
      ++stats.keyframes_moved;
    } else {
      const Sim3d world = worldFor(kf);
      // No corrected ancestor (a part of the map the correction did not touch): left as it is,
      // not rewritten (each rewrite is a pose change the store and the slices pass on).
      if (isIdentity(world)) continue;
      new_poses.emplace_back(kf, (Sim3d(kf->pose()) * world.inverse()).toSE3());
      ++stats.keyframes_propagated;
    }
  }
  // The points that can move: those the correction names and those of the keyframes it moves (a
  // point's anchor, its reference keyframe, is one of its observers). Not every point of the map:
  // a store of many maps holds ~1M points, and sorting and walking them all took ~350 ms of each
  // loop's correction there (session 31), for the few thousand that move.
  std::vector<MapPoint*> candidates;
  std::unordered_set<const MapPoint*> seen;
  const auto consider = [&](MapPoint* p) {
    if (p != nullptr && !p->isBad() && seen.insert(p).second) candidates.push_back(p);
  };
  for (const auto& [p, position] : correction.point_positions) consider(p);
  for (const auto& [p, anchor] : correction.point_anchor) consider(p);
  for (const auto& [kf, pose] : new_poses) {
    for (MapPoint* p : kf->points()) consider(p);
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const MapPoint* a, const MapPoint* b) { return a->id() < b->id(); });
  std::vector<std::pair<MapPoint*, Eigen::Vector3d>> new_positions;
  for (MapPoint* p : candidates) {
    if (const auto it = correction.point_positions.find(p);
        it != correction.point_positions.end()) {
      new_positions.emplace_back(p, it->second);
      continue;
    }
    KeyFrame* anchor = p->referenceKeyFrame();
    if (const auto it = correction.point_anchor.find(p); it != correction.point_anchor.end()) {
      anchor = it->second;
    }
    if (anchor == nullptr) continue;
    const Eigen::Vector3d moved = worldFor(anchor) * p->position();
    if (moved != p->position()) new_positions.emplace_back(p, moved);
  }
  // Poses first: a point's viewing direction and distance range follow from the cameras.
  for (const auto& [kf, pose] : new_poses) map.setKeyFramePose(kf, pose);
  for (const auto& [p, position] : new_positions) {
    map.relocatePoint(p, position);
    ++stats.points_moved;
  }
  return stats;
}

}  // namespace edgeslam
