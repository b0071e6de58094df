#pragma once
// `run --localize-only --route NAME`: a localising client following a route of the stored map
// gets an instruction every frame (instructions.csv, the progress line, the viewer), and
// metrics.json's "navigation" says how many checkpoints the true path passed within a radius of
// (paper Sec. VI: 0.5 m).
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "eval/alignment.h"
#include "geometry/se3.h"
#include "io/trajectory.h"
#include "nav/navigator.h"

namespace edgeslam::cli {

struct RouteFollowingOptions {
  double success_radius_m = 0.5;  // the truth's: a checkpoint passed this close counts reached
  NavigatorOptions navigator;
};

class RouteFollowing {
 public:
  // Reads the route from the store (read-only). Throws std::runtime_error naming the store, map
  // and route when there is no such route.
  RouteFollowing(const std::filesystem::path& store_directory, const std::string& map,
                 const std::string& route, RouteFollowingOptions options);

  // Each frame, with the camera's pose in the map's frame when it has one.
  const Instruction& addFrame(std::size_t frame, double timestamp, const std::optional<SE3d>& T_cw);
  const Instruction& last() const { return instructions_.back().instruction; }
  std::string lastText() const;
  // The checkpoint the latest instruction leads to or reached (0-based); -1 before any.
  int lastCheckpoint() const;
  const std::vector<Eigen::Vector3d>& checkpoints() const {
    return navigator_->route().checkpoints;
  }

  // instructions.csv: frame,timestamp,instruction,checkpoint,turn_deg,distance_m,text.
  void writeInstructions(const std::filesystem::path& path) const;
  // metrics.json "navigation". `stored_keyframes`: the stored map's keyframe poses (map frame),
  // aligned to `ground_truth` (this run's frames) by timestamp to take the checkpoints into the
  // truth's frame; when too few of them fall among this run's frames, the run's own poses
  // (`localised`) are aligned instead (said in "alignment").
  nlohmann::json json(const Trajectory& ground_truth, const Trajectory& stored_keyframes,
                      const Trajectory& localised, AlignMode align) const;

 private:
  struct Entry {
    std::size_t frame = 0;
    double timestamp = 0.0;
    Instruction instruction;
  };
  std::string map_;
  std::string unit_ = "m";  // of the map's distances: "map units" when it has no metric scale
  RouteFollowingOptions options_;
  std::optional<Navigator> navigator_;
  std::vector<Entry> instructions_;
};

}  // namespace edgeslam::cli
