#pragma once
// Pieces of a run's metrics.json and summary that one mode alone has, or that several commands
// share: kept out of the run command so that it reads as the run's steps.
#include <nlohmann/json.hpp>
#include <optional>

#include "client/tracking_types.h"
#include "eval/alignment.h"
#include "io/frame_range.h"
#include "io/trajectory.h"
#include "modes/adaptation_loop.h"
#include "modes/slam_system.h"
#include "modes/split_client_report.h"
#include "util/timing_stats.h"

namespace edgeslam::cli {

nlohmann::json toJson(const PercentileSummary& s);
// "dataset_frames": where the played frames start in the dataset and how many were played.
// With several ranges, "ranges": [{first, last}, ...] too.
nlohmann::json frameRangeJson(const std::optional<std::vector<FrameRange>>& ranges,
                              std::size_t played);
nlohmann::json keyFrameDecisionsJson(const KeyFrameDecisionCounts& c);
// ATE of `est` against `gt`; nullopt when there are too few pairs for the alignment.
std::optional<nlohmann::json> ateJson(const Trajectory& gt, const Trajectory& est, AlignMode align);
// "adapt": the self-adaptation loop's switches, probes and network estimates.
nlohmann::json adaptationJson(const AdaptationLoop& loop);
// Edge mode's "client_map", "resync" and "client_triangulation".
void addSplitClientMetrics(nlohmann::json& metrics, const SplitClientReport& split,
                           const SlamCounters& counters, int client_map_window);
// The summary's route line, from metrics.json "navigation".
void printRouteSummary(const nlohmann::json& navigation);

}  // namespace edgeslam::cli
