#include "mapping/map_part_merge.h"

#include <vector>

namespace edgeslam {

std::unordered_set<KeyFrame*> connectedPart(KeyFrame* start) {
  std::unordered_set<KeyFrame*> part{start};
  std::vector<KeyFrame*> frontier{start};
  const auto reach = [&](KeyFrame* kf) {
    if (kf != nullptr && !kf->isBad() && part.insert(kf).second) frontier.push_back(kf);
  };
  while (!frontier.empty()) {
    KeyFrame* kf = frontier.back();
    frontier.pop_back();
    for (const auto& [other, weight] : kf->connections()) reach(other);
    // A keyframe just inserted, before mapping links it, is tied to the map by its points only.
    for (MapPoint* p : kf->points()) {
      if (p == nullptr || p->isBad()) continue;
      for (const auto& [id, observation] : p->observations()) reach(observation.keyframe);
    }
    reach(kf->parent());
    for (KeyFrame* child : kf->children()) reach(child);
    for (KeyFrame* other : kf->loopEdges()) reach(other);
  }
  return part;
}

namespace {

// Moves every keyframe of `part` and every point its keyframes see by the world similarity
// `world` (new world point = world * old world point).
void movePart(Map& map, const std::unordered_set<KeyFrame*>& part, const Sim3d& world,
              MapPartMerge& out) REQUIRES(map.updateMutex()) {
  const Sim3d back = world.inverse();
  std::unordered_set<MapPoint*> points;
  for (KeyFrame* kf : part) {
    for (MapPoint* p : kf->points()) {
      if (p != nullptr && !p->isBad()) points.insert(p);
    }
  }
  for (KeyFrame* kf : part) {
    map.setKeyFramePose(kf, (Sim3d(kf->pose()) * back).toSE3());
    out.moved.push_back(kf->id());
    ++out.keyframes_moved;
  }
  out.world = world;
  for (MapPoint* p : points) {
    map.relocatePoint(p, world * p->position());
    ++out.points_moved;
  }
}

}  // namespace

MapPartMerge mergeSeparateParts(Map& map, VerifiedLoop& loop) {
  MapPartMerge out;
  const std::unordered_set<KeyFrame*> current_part = connectedPart(loop.current);
  if (current_part.contains(loop.loop)) return out;
  out.merged = true;
  // Current-side world to loop-side world: the current keyframe's pose now and the one the loop
  // gives it.
  const Sim3d current_to_loop = loop.S_cw.inverse() * Sim3d(loop.current->pose());
  KeyFrame* origin = map.originKeyFrame();
  const bool current_has_origin = origin != nullptr && current_part.contains(origin);
  if (!current_has_origin) {
    out.moved_current_side = true;
    movePart(map, current_part, current_to_loop, out);
    map.hangTreeFrom(loop.current, loop.loop);
    // The current keyframe is where the loop wants it: S_cw is its pose now.
    loop.S_cw = Sim3d(loop.current->pose());
  } else {
    movePart(map, connectedPart(loop.loop), current_to_loop.inverse(), out);
    map.hangTreeFrom(loop.loop, loop.current);
    loop.S_cw = loop.S_cw * current_to_loop;
  }
  return out;
}

}  // namespace edgeslam
