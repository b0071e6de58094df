#pragma once
// What a finished run reports: metrics.json (the CONTRACT's keys), the summary on stdout, and the
// output folder's trajectories, frames.csv and instructions.csv.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "eval/alignment.h"
#include "io/dataset.h"
#include "io/trajectory.h"
#include "modes/slam_system.h"
#include "optimize/map_optimization.h"
#include "run_frame_loop.h"
#include "run_options.h"

namespace edgeslam::cli {

// The run as it was set up.
struct RunSetup {
  const RunOptions& options;
  const DatasetInfo& info;
  std::string sensor_name;
  Sensor sensor = Sensor::kMonocular;
  std::size_t frame_count = 0;
};

class RunReport {
 public:
  // Call after slam.finish(). `store_metrics`: what the edge's map store holds (null without one).
  RunReport(const RunSetup& setup, const PlayedFrames& played, const SlamSystem& slam,
            const RunCompanions& companions, nlohmann::json store_metrics, double wall_s);

  const nlohmann::json& metrics() const { return metrics_; }
  void printSummary() const;
  // Nothing without --out.
  void writeOutputs() const;

 private:
  nlohmann::json commonMetrics() const;
  // Frames tracked in a map's own frame: {"at_frame_time", "never_merged"}.
  nlohmann::json ownFramesJson() const;
  void addModeMetrics();
  nlohmann::json computeBudgetJson() const;
  std::string computeBudgetLine() const;

  const RunSetup& setup_;
  const PlayedFrames& played_;
  const SlamSystem& slam_;
  const RunCompanions& companions_;
  nlohmann::json store_metrics_;
  double wall_s_;
  AlignMode align_;
  Trajectory at_time_;
  Trajectory final_;
  // Frame-time poses left out of at_time_: a map's own frame (before a merge, or for good).
  std::vector<OwnMapTrajectory> own_frames_;
  std::optional<nlohmann::json> ate_;
  std::optional<nlohmann::json> ate_final_;
  SlamCounters counters_;
  std::optional<TrackingDiagnostics> diagnostics_;
  std::optional<MapIntrinsicsRefinement> refinement_;
  std::vector<std::string> warnings_;
  nlohmann::json metrics_;
};

}  // namespace edgeslam::cli
