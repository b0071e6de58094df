#include "mapping/loop_correction.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <unordered_map>
#include <unordered_set>
#include <utility>

#include "map/map_matching.h"
#include "mapping/loop_map_correction.h"
#include "mapping/map_part_merge.h"
#include "optimize/pose_graph.h"
#include "util/timing_stats.h"

namespace edgeslam {
namespace {

constexpr double kRadToDeg = 57.29577951308232;

using KeyFramePair = std::pair<KeyFrameId, KeyFrameId>;
KeyFramePair orderedPair(const KeyFrame* a, const KeyFrame* b) {
  return a->id() < b->id() ? KeyFramePair{a->id(), b->id()} : KeyFramePair{b->id(), a->id()};
}

// What phase one hands to the graph solve: the graph and, per vertex, the pose the map's points
// are consistent with when it is applied.
struct GraphSnapshot {
  PoseGraph graph;
  std::vector<KeyFrame*> vertex_keyframes;
  std::vector<Sim3d> before;
  std::unordered_map<MapPoint*, KeyFrame*> point_anchor;
};

// The keyframes the essential graph joins to `seed` (spanning tree, loop edges, covisibility of
// at least `min_weight`): what a correction can move. A part of the map joined to them by none
// of those would be vertices without an edge to the loop, left where they are by the solve at
// the cost of their own edges (a store of unconnected maps: nearly all of the work). Sorted by id.
std::vector<KeyFrame*> essentialGraphPart(KeyFrame* seed, int min_weight) {
  std::vector<KeyFrame*> part{seed};
  std::unordered_set<const KeyFrame*> seen{seed};
  const auto visit = [&](KeyFrame* kf) {
    if (kf != nullptr && !kf->isBad() && seen.insert(kf).second) part.push_back(kf);
  };
  for (std::size_t next = 0; next < part.size(); ++next) {
    const KeyFrame* kf = part[next];
    visit(kf->parent());
    for (KeyFrame* child : kf->children()) visit(child);
    for (KeyFrame* other : kf->loopEdges()) visit(other);
    for (KeyFrame* other : kf->covisiblesWithWeightAtLeast(min_weight)) visit(other);
  }
  std::sort(part.begin(), part.end(), KeyFrameIdLess{});
  return part;
}

}  // namespace

LoopCorrectionResult correctLoop(Map& map, const VerifiedLoop& verified,
                                 const PinholeCamera& camera, const LoopCorrectionOptions& options,
                                 const std::function<void(const MapPartMerge&)>& on_merged) {
  LoopCorrectionResult result;
  VerifiedLoop loop = verified;  // a merge of two parts re-expresses S_cw
  KeyFrame* current = loop.current;
  KeyFrame* loop_kf = loop.loop;
  GraphSnapshot snapshot;
  SE3d current_before;
  Stopwatch prepare_timer;
  {
    MutexLock lock(map.updateMutex());
    if (current->isBad() || loop_kf->isBad()) return result;
    // 0. Two parts of the map that shared nothing: one is moved onto the other first.
    result.merge = mergeSeparateParts(map, loop);
    result.merged_keyframes_moved = result.merge.keyframes_moved;
    result.merged_points_moved = result.merge.points_moved;
    if (result.merge.merged && on_merged) on_merged(result.merge);
    current_before = current->pose();
    map.updateConnections(current);

    // 1. The current neighbourhood onto the loop side: each keyframe keeps its pose relative to
    //    the current one, and its points their coordinates in that keyframe.
    std::vector<KeyFrame*> neighbourhood{current};
    for (const auto& [kf, weight] : current->connections()) {
      if (!kf->isBad()) neighbourhood.push_back(kf);
    }
    std::unordered_map<KeyFrame*, Sim3d> corrected;    // S_iw on the loop side
    std::unordered_map<KeyFrame*, Sim3d> uncorrected;  // S_iw as it was
    const SE3d T_wc = current->poseInverse();
    for (KeyFrame* kf : neighbourhood) {
      uncorrected[kf] = Sim3d(kf->pose());
      corrected[kf] = kf == current ? loop.S_cw : Sim3d(kf->pose() * T_wc) * loop.S_cw;
    }
    std::vector<std::pair<MapPoint*, Eigen::Vector3d>> moved_points;
    for (KeyFrame* kf : neighbourhood) {
      const Sim3d to_new_world = corrected[kf].inverse() * uncorrected[kf];
      for (MapPoint* p : kf->points()) {
        if (p == nullptr || p->isBad() || snapshot.point_anchor.contains(p)) continue;
        snapshot.point_anchor.emplace(p, kf);
        moved_points.emplace_back(p, to_new_world * p->position());
      }
    }
    for (KeyFrame* kf : neighbourhood) map.setKeyFramePose(kf, corrected[kf].toSE3());
    for (const auto& [p, position] : moved_points) map.relocatePoint(p, position);

    // 2. The loop's points replace the current keyframe's duplicates, then the whole loop
    //    neighbourhood is fused into the current neighbourhood.
    std::unordered_map<KeyFrame*, KeyFrameSet> links_before;
    for (KeyFrame* kf : neighbourhood) {
      for (const auto& [other, weight] : kf->connections()) links_before[kf].insert(other);
    }
    for (std::size_t i = 0; i < loop.matched.size(); ++i) {
      MapPoint* loop_point = loop.matched[i];
      if (loop_point == nullptr || loop_point->isBad()) continue;
      MapPoint* own = current->point(i);
      if (own != nullptr && !own->isBad()) {
        if (own != loop_point) {
          map.replacePoint(own, loop_point);
          ++result.points_replaced;
        }
      } else {
        map.addObservation(loop_point, current, i);
        map.refreshPoint(loop_point);
      }
    }
    for (KeyFrame* kf : neighbourhood) {
      if (!kf->isBad()) {
        result.points_replaced +=
            static_cast<std::size_t>(fuse(map, kf, loop.loop_points, camera, options.fuse_radius));
      }
    }

    // 3. New covisibility links across the loop.
    std::map<KeyFrame*, KeyFrameSet, KeyFrameIdLess> new_links;
    const KeyFrameSet in_neighbourhood(neighbourhood.begin(), neighbourhood.end());
    for (KeyFrame* kf : neighbourhood) {
      if (kf->isBad()) continue;
      map.updateConnections(kf);
      for (const auto& [other, weight] : kf->connections()) {
        if (links_before[kf].contains(other) || in_neighbourhood.contains(other)) continue;
        new_links[kf].insert(other);
        ++result.new_links;
      }
    }
    map.addLoopEdge(current, loop_kf);

    // 4. The essential graph over the keyframes it joins to the loop. New links state the
    //    corrected relation; all other constraints keep the relative poses the map had before.
    std::unordered_map<const KeyFrame*, std::size_t> vertex_of;
    for (KeyFrame* kf : essentialGraphPart(loop_kf, options.min_covisibility_weight)) {
      vertex_of.emplace(kf, snapshot.vertex_keyframes.size());
      snapshot.vertex_keyframes.push_back(kf);
      const auto c = corrected.find(kf);
      const Sim3d initial = c != corrected.end() ? c->second : Sim3d(kf->pose());
      snapshot.before.push_back(initial);
      snapshot.graph.vertices.push_back({kf->id(), initial, kf == loop_kf});
    }
    const auto unchanged = [&](KeyFrame* kf) {
      const auto u = uncorrected.find(kf);
      return u != uncorrected.end() ? u->second : snapshot.before[vertex_of.at(kf)];
    };
    std::set<KeyFramePair> linked;
    const auto addEdge = [&](KeyFrame* from, KeyFrame* to, const Sim3d& S_from, const Sim3d& S_to) {
      const auto i = vertex_of.find(from);
      const auto j = vertex_of.find(to);
      if (i == vertex_of.end() || j == vertex_of.end() || from == to) return;
      if (!linked.insert(orderedPair(from, to)).second) return;
      snapshot.graph.edges.push_back(
          {i->second, j->second, S_to * S_from.inverse(), Eigen::Matrix<double, 7, 7>::Identity()});
    };
    for (const auto& [kf, others] : new_links) {
      for (KeyFrame* other : others) {
        const bool the_loop = kf == current && other == loop_kf;
        if (!the_loop && kf->weight(other) < options.min_covisibility_weight) continue;
        const auto i = vertex_of.find(kf);
        const auto j = vertex_of.find(other);
        if (i == vertex_of.end() || j == vertex_of.end()) continue;
        addEdge(kf, other, snapshot.before[i->second], snapshot.before[j->second]);
      }
    }
    for (KeyFrame* kf : snapshot.vertex_keyframes) {
      if (KeyFrame* parent = kf->parent(); parent != nullptr && !parent->isBad()) {
        addEdge(parent, kf, unchanged(parent), unchanged(kf));
      }
      for (KeyFrame* other : kf->loopEdges()) {
        if (!other->isBad()) addEdge(other, kf, unchanged(other), unchanged(kf));
      }
      for (KeyFrame* other : kf->covisiblesWithWeightAtLeast(options.min_covisibility_weight)) {
        if (!other->isBad()) addEdge(other, kf, unchanged(other), unchanged(kf));
      }
    }
    result.neighbourhood = neighbourhood.size();
  }
  result.prepare_ms = prepare_timer.elapsedMs();

  // 5. Solve without the lock (mapping is paused by the caller; tracking goes on).
  result.graph_vertices = snapshot.graph.vertices.size();
  result.graph_edges = snapshot.graph.edges.size();
  PoseGraphOptions graph_options;
  graph_options.max_iterations = options.pose_graph_iterations;
  graph_options.fix_scale = options.fix_scale;
  Stopwatch timer;
  const PoseGraphResult solved = optimizePoseGraph(snapshot.graph, graph_options);
  result.pose_graph_ms = timer.elapsedMs();

  Stopwatch apply_timer;
  MutexLock lock(map.updateMutex());
  MapCorrection correction;
  for (std::size_t v = 0; v < snapshot.vertex_keyframes.size(); ++v) {
    KeyFrame* kf = snapshot.vertex_keyframes[v];
    if (kf->isBad()) continue;
    correction.keyframes.emplace(kf, KeyFrameCorrection{snapshot.before[v], solved.S_cw[v]});
  }
  correction.point_anchor = std::move(snapshot.point_anchor);
  applyMapCorrection(map, correction);
  result.apply_ms = apply_timer.elapsedMs();

  const SE3d change = current->pose() * current_before.inverse();
  result.translation_m = (current->cameraCenter() - current_before.inverse().translation()).norm();
  result.rotation_deg = Eigen::AngleAxisd(change.rotation()).angle() * kRadToDeg;
  result.scale = loop.S_cl.scale();
  result.done = true;
  return result;
}

}  // namespace edgeslam
