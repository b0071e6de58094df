#pragma once
// A loop between two parts of the map that share nothing yet: two clients mapping one map, or a
// session that began on a map of its own before it could relocalise. Before the loop's ordinary
// correction, the part without the map's origin is moved whole onto the other (SE(3) with depth,
// Sim(3) for monocular), and their spanning trees are joined; the correction that follows then
// only refines the seam. Callers hold the map's update mutex.
#include <cstddef>
#include <unordered_set>
#include <vector>

#include "geometry/sim3.h"
#include "map/map.h"
#include "mapping/loop_verifier.h"

namespace edgeslam {

// Keyframes reachable from `start` through covisibility links, shared points, the spanning tree
// and loop edges.
std::unordered_set<KeyFrame*> connectedPart(KeyFrame* start);

struct MapPartMerge {
  bool merged = false;  // false: both ends of the loop were in one part already
  bool moved_current_side = false;
  std::size_t keyframes_moved = 0;
  std::size_t points_moved = 0;
  // The move: new world point = world * old world point, for the points of these keyframes.
  Sim3d world;
  std::vector<KeyFrameId> moved;
};

// When loop.current and loop.loop are in separate parts: moves one part (the one without the
// map's origin keyframe; the current side when neither has it) so that the loop's relation
// holds, hangs its spanning tree from the other end of the loop, and updates loop.S_cw to the
// frame the current keyframe is in afterwards.
MapPartMerge mergeSeparateParts(Map& map, VerifiedLoop& loop) REQUIRES(map.updateMutex());

}  // namespace edgeslam
