#pragma once
// What the web viewer shows at one moment, and its JSON encoding (the `/api/state` body and each
// `/api/events` message; fields in docs/viewer.md).
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace edgeslam::viz {

// The run's figures after its latest frame.
struct RunStatus {
  std::size_t frame = 0;  // frames processed so far
  std::size_t frames_total = 0;
  double fps = 0.0;
  std::string state = "starting";  // tracking state of the latest frame (ok, lost, ...)
  int tracked_points = 0;
  std::size_t keyframes = 0;
  std::size_t map_points = 0;
  double client_ms = 0.0;  // the latest frame's client processing time
  double e2e_ms = 0.0;     // the latest frame's end-to-end latency (arrival to pose)
  std::uint64_t uplink_bytes = 0;
  std::uint64_t downlink_bytes = 0;
  std::string mode;
  std::string sensor;
  std::string link;         // the emulated link profile ("none" without one)
  int adaptation_row = -1;  // Table I row in use (0-based); -1 without self-adaptation
  bool finished = false;    // the run is over (the viewer lingers on the final map)
  std::string instruction;  // following a route: the latest navigation instruction ("" without)
  int checkpoint = -1;      // following a route: the checkpoint it leads to (0-based; -1 without)
};

struct ViewPose {
  Eigen::Vector3d position = Eigen::Vector3d::Zero();
  Eigen::Quaterniond orientation = Eigen::Quaterniond::Identity();  // camera-to-world
};

struct ViewSnapshot {
  std::uint64_t version = 0;  // grows with every published frame
  RunStatus status;
  std::optional<ViewPose> camera;  // the latest tracked camera pose
  std::vector<Eigen::Vector3d> trajectory;
  std::vector<Eigen::Vector3d> ground_truth;  // in the trajectory's frame; empty without one
  std::vector<ViewPose> keyframes;
  std::vector<Eigen::Vector3d> points;
  std::size_t points_total = 0;        // in the map the points were sampled from
  std::vector<Eigen::Vector3d> route;  // checkpoints of the route followed, in order; or none
};

// Positions are rounded to the millimetre and flattened ([x0, y0, z0, x1, ...]) to keep the
// message small; anything not finite is left out (a position) or written as 0 (a figure).
nlohmann::json toJson(const ViewSnapshot& snapshot);
// The same encodings for other views: positions flattened, a pose (nullopt when not finite).
nlohmann::json flatPositions(const std::vector<Eigen::Vector3d>& positions);
std::optional<nlohmann::json> poseJson(const ViewPose& pose);

}  // namespace edgeslam::viz
