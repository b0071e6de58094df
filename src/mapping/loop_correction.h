#pragma once
// Closing a verified loop: the current keyframe's neighbourhood is moved onto the loop side of the
// map by the estimated similarity (with its points), the loop's points replace their duplicates,
// the covisibility graph gains the new links and a loop edge, and an essential-graph optimisation
// (spanning tree, loop edges, strong covisibility, the new links) spreads the correction over the
// whole map (optimize/pose_graph.h). Takes the map's update mutex itself; the graph is solved
// without it, and keyframes made meanwhile follow their spanning-tree parents.
#include <cstddef>
#include <functional>

#include "geometry/camera.h"
#include "map/map.h"
#include "mapping/loop_verifier.h"
#include "mapping/map_part_merge.h"

namespace edgeslam {

struct LoopCorrectionOptions {
  bool fix_scale = false;  // stereo / RGB-D: SE(3) graph
  int pose_graph_iterations = 20;
  int min_covisibility_weight = 100;  // covisibility links strong enough to join the graph
  float fuse_radius = 4.f;            // px at level 0, loop points fused into the neighbourhood
};

struct LoopCorrectionResult {
  bool done = false;              // false when the loop's keyframes were culled meanwhile
  std::size_t neighbourhood = 0;  // keyframes moved with the current one
  std::size_t points_replaced = 0;
  std::size_t new_links = 0;
  std::size_t graph_vertices = 0;
  std::size_t graph_edges = 0;
  // How far the loop moved the current keyframe (camera centre, rotation), and its scale change.
  double translation_m = 0.0;
  double rotation_deg = 0.0;
  double scale = 1.0;
  double pose_graph_ms = 0.0;
  // The rest of the correction: the neighbourhood moved, points fused and the graph built (under
  // the map mutex), and the solution applied to the map (under it again).
  double prepare_ms = 0.0;
  double apply_ms = 0.0;
  // A loop between two parts of the map that shared nothing (mergeSeparateParts): how much of
  // the map was moved onto the other part before the correction. 0 for an ordinary loop.
  std::size_t merged_keyframes_moved = 0;
  std::size_t merged_points_moved = 0;
  MapPartMerge merge;
};

// `on_merged` is told of a merge of two parts (mergeSeparateParts) as soon as it is made, under
// the map's update mutex (it must not take it): keyframes inserted after that are the caller's.
LoopCorrectionResult correctLoop(Map& map, const VerifiedLoop& loop, const PinholeCamera& camera,
                                 const LoopCorrectionOptions& options,
                                 const std::function<void(const MapPartMerge&)>& on_merged = {})
    EXCLUDES(map.updateMutex());

}  // namespace edgeslam
