#include "viz/edge_map_json.h"

#include <algorithm>
#include <map>
#include <unordered_map>

#include "store/stored_map_loader.h"
#include "viz/view_snapshot.h"

namespace edgeslam::viz {

nlohmann::json edgeMapJson(const EdgeMapContent& map, std::size_t max_keyframes) {
  const MapSample& sample = map.sample;
  const std::size_t n = sample.keyframe_poses.size();
  const bool with_ids = sample.keyframe_ids.size() == n;

  // Keyframes made by each client, in the order they were made (ids grow per client).
  std::map<std::uint8_t, std::vector<std::pair<KeyFrameId, Eigen::Vector3d>>> by_origin;
  std::unordered_map<KeyFrameId, Eigen::Vector3d> position_of;
  for (std::size_t i = 0; i < n; ++i) {
    const KeyFrameId id = with_ids ? sample.keyframe_ids[i] : i;
    const Eigen::Vector3d position = sample.keyframe_poses[i].translation();
    by_origin[with_ids ? idOrigin(id) : 0].emplace_back(id, position);
    position_of.emplace(id, position);
  }
  nlohmann::json trajectories = nlohmann::json::array();
  for (auto& [origin, keyframes] : by_origin) {
    std::sort(keyframes.begin(), keyframes.end(),
              [](const auto& a, const auto& b) { return a.first < b.first; });
    std::vector<Eigen::Vector3d> positions;
    positions.reserve(keyframes.size());
    for (const auto& [id, position] : keyframes) positions.push_back(position);
    trajectories.push_back({{"origin", origin}, {"positions", flatPositions(positions)}});
  }

  nlohmann::json keyframes = nlohmann::json::array();
  const std::size_t step = std::max<std::size_t>(1, (n + max_keyframes - 1) / max_keyframes);
  for (std::size_t i = 0; i < n; ++i) {
    if ((n - 1 - i) % step != 0) continue;
    const SE3d& pose = sample.keyframe_poses[i];
    if (auto encoded = poseJson({pose.translation(), pose.rotation()})) {
      keyframes.push_back(std::move(*encoded));
    }
  }

  nlohmann::json loops = nlohmann::json::array();
  for (const LoopEvent& loop : map.loops) {
    const auto from = position_of.find(loop.current);
    const auto to = position_of.find(loop.loop);
    if (from == position_of.end() || to == position_of.end()) continue;
    loops.push_back({{"from", flatPositions({from->second})},
                     {"to", flatPositions({to->second})},
                     {"merge", loop.keyframes_merged > 0},
                     {"frames", {loop.current_frame, loop.loop_frame}}});
  }

  nlohmann::json routes = nlohmann::json::array();
  for (const RouteRecord& route : map.routes) {
    routes.push_back({{"name", route.name}, {"checkpoints", flatPositions(route.checkpoints)}});
  }

  return {{"keyframe_count", n},
          {"map_points", sample.total_points},
          {"points", flatPositions(sample.points)},
          {"keyframes", std::move(keyframes)},
          {"trajectories", std::move(trajectories)},
          {"loops", std::move(loops)},
          {"routes", std::move(routes)}};
}

std::optional<SE3d> newestKeyFrameOf(const MapSample& sample, std::uint8_t origin) {
  std::optional<SE3d> newest;
  KeyFrameId newest_id = kInvalidId;
  for (std::size_t i = 0; i < sample.keyframe_ids.size() && i < sample.keyframe_poses.size(); ++i) {
    const KeyFrameId id = sample.keyframe_ids[i];
    if (idOrigin(id) == origin && (!newest || id > newest_id)) {
      newest = sample.keyframe_poses[i];
      newest_id = id;
    }
  }
  return newest;
}

MapSample sampleOfStoredMap(StoredMap& map, std::size_t max_points) {
  MapSample sample;
  const StoredSession* session = latestSessionWithKeyFrames(map);
  if (session == nullptr) return sample;
  for (const KeyFrameRecord& kf : session->keyframes) {
    sample.keyframe_poses.push_back(kf.T_cw.inverse());
    sample.keyframe_ids.push_back(kf.id);
  }
  const std::size_t count = session->points.size();
  sample.total_points = count;
  if (max_points > 0 && count > 0) {
    const std::size_t stride = (count + max_points - 1) / max_points;
    for (std::size_t i = 0; i < count; i += stride) {
      sample.points.push_back(session->points[i].position);
    }
  }
  return sample;
}

}  // namespace edgeslam::viz
