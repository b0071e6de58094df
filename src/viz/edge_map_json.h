#pragma once
// One map of the edge view as JSON (docs/viewer.md, "maps"): a sample of its points, its keyframes,
// one trajectory per client (its keyframes in the order they were made, told apart by the top
// byte of their ids), its loops and merges as segments between the two keyframes, its routes.
// Shared by the maps sessions write now and the maps the store holds.
#include <cstddef>
#include <nlohmann/json.hpp>
#include <optional>
#include <vector>

#include "mapping/loop_closer.h"
#include "modes/slam_system.h"
#include "store/map_store.h"

namespace edgeslam::viz {

struct EdgeMapContent {
  MapSample sample;  // keyframe_ids filled
  std::vector<LoopEvent> loops;
  std::vector<RouteRecord> routes;
};

// Keys "keyframe_count", "map_points", "points", "keyframes" (at most `max_keyframes`, evenly
// spaced, the newest kept), "trajectories" ([{origin, positions}]), "loops" ([{from, to, merge,
// frames}]; a loop whose keyframe is gone is left out), "routes" ([{name, checkpoints}]).
nlohmann::json edgeMapJson(const EdgeMapContent& map, std::size_t max_keyframes);

// The newest keyframe made by `origin`'s client in `sample` (its live position on the edge).
std::optional<SE3d> newestKeyFrameOf(const MapSample& sample, std::uint8_t origin);

// A stored map's latest session with keyframes, as a sample with at most `max_points` points.
MapSample sampleOfStoredMap(StoredMap& map, std::size_t max_points);

}  // namespace edgeslam::viz
