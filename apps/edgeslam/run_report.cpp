#include "run_report.h"

#include <fmt/format.h>
#include <fmt/ranges.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <fstream>
#include <numeric>

#include "intrinsics_report.h"
#include "map_store_option.h"
#include "modes/adaptation_loop.h"
#include "modes/run_warnings.h"
#include "route_following.h"
#include "run_metrics.h"
#include "run_viewer.h"
#include "semantic_evaluation.h"
#include "tracking_diagnostics_json.h"

namespace edgeslam::cli {
namespace {

// Maps started after a loss that no merge joined back (each merge joins one; never negative).
std::size_t unmergedMaps(const std::vector<std::size_t>& started,
                         const std::vector<LoopFramesRecord>& loops) {
  return started.size() - mapsTiedBack(started, loops);
}

// Frames by the age of their mask: median / p90 / max and coarse buckets (docs/semantic.md).
nlohmann::json maskAgeJson(const std::array<std::uint64_t, 65>& by_age) {
  const std::uint64_t total = std::accumulate(by_age.begin(), by_age.end(), std::uint64_t{0});
  const auto quantile = [&](double q) -> nlohmann::json {
    if (total == 0) return nullptr;
    std::uint64_t seen = 0;
    for (std::size_t age = 0; age < by_age.size(); ++age) {
      seen += by_age[age];
      if (static_cast<double>(seen) >= q * static_cast<double>(total)) return age;
    }
    return by_age.size() - 1;
  };
  std::size_t last = 0;
  for (std::size_t age = 0; age < by_age.size(); ++age) {
    if (by_age[age] > 0) last = age;
  }
  nlohmann::json buckets = nlohmann::json::object();
  const auto bucket = [&](const char* name, std::size_t from, std::size_t to) {
    buckets[name] =
        std::accumulate(by_age.begin() + static_cast<std::ptrdiff_t>(from),
                        by_age.begin() + static_cast<std::ptrdiff_t>(to + 1), std::uint64_t{0});
  };
  bucket("0", 0, 0);
  bucket("1", 1, 1);
  bucket("2", 2, 2);
  bucket("3-4", 3, 4);
  bucket("5-8", 5, 8);
  bucket("9-16", 9, 16);
  bucket("17-32", 17, 32);
  bucket(">32", 33, by_age.size() - 1);
  return {{"frames", total},
          {"median", quantile(0.5)},
          {"p90", quantile(0.9)},
          {"max", total == 0 ? nlohmann::json(nullptr) : nlohmann::json(last)},
          {"buckets", std::move(buckets)}};
}

}  // namespace

RunReport::RunReport(const RunSetup& setup, const PlayedFrames& played, const SlamSystem& slam,
                     const RunCompanions& companions, nlohmann::json store_metrics, double wall_s)
    : setup_(setup),
      played_(played),
      slam_(slam),
      companions_(companions),
      store_metrics_(std::move(store_metrics)),
      wall_s_(wall_s),
      align_(setup.sensor == Sensor::kMonocular ? AlignMode::kSim3 : AlignMode::kSe3),
      at_time_(slam.trajectoryAtFrameTime()),
      final_(slam.trajectoryFinal()),
      own_frames_(slam.trajectoriesInOwnFrames()),
      ate_(ateJson(played.ground_truth, at_time_, align_)),
      ate_final_(ateJson(played.ground_truth, final_, align_)),
      counters_(slam.counters()),
      diagnostics_(slam.trackingDiagnostics()),
      refinement_(slam.intrinsicsRefinement()) {
  const RunOptions& options = setup.options;
  warnings_ = runWarnings(
      {.frames = setup.frame_count,
       .tracked = played.tracked,
       .lost = played.lost,
       .frames_dropped_late = played.frames_skipped_late,
       .backend_busy_refusals = counters_.backend.busy_refusals,
       .backend_wait_ms = counters_.backend.wait_total_ms,
       .wall_ms = wall_s * 1000.0,
       .monocular = setup.sensor == Sensor::kMonocular,
       .keyframe_depth_ratio = counters_.map.keyframe_depth_ratio,
       .frames_out_of_order = played.frame_order.rejected(),
       .frames_without_map = diagnostics_ ? diagnostics_->frames_without_map : 0,
       .map_built =
           !diagnostics_ || diagnostics_->initialized_at_frame.has_value() || options.localize_only,
       .refusals = diagnostics_ ? refusalSummary(*diagnostics_) : std::string(),
       // Merges are counted in-process (local mode) or told in slices (edge mode).
       .maps_unmerged = options.mode == "local" || options.mode == "edge"
                            ? unmergedMaps(slam.mapsStartedAt(), counters_.map.loop_frames)
                            : 0});
  if (std::string store_warning = storeWarning(store_metrics_, slam.keyFrameCount());
      !store_warning.empty()) {
    warnings_.push_back(std::move(store_warning));
  }
  metrics_ = commonMetrics();
  addModeMetrics();
}

nlohmann::json RunReport::ownFramesJson() const {
  std::size_t at_frame_time = 0;
  std::size_t never_merged = 0;
  for (const OwnMapTrajectory& own : own_frames_) {
    at_frame_time += own.poses.size();
    never_merged += own.never_joined;
  }
  return {{"at_frame_time", at_frame_time}, {"never_merged", never_merged}};
}

nlohmann::json RunReport::commonMetrics() const {
  const RunOptions& options = setup_.options;
  const EdgeExchangeCounters& exchange = counters_.exchange;
  const BackendPacing& backend = counters_.backend;
  const FrameOrderGuard& order = played_.frame_order;
  const std::size_t keyframes_uploaded = std::max<std::size_t>(1, exchange.keyframes_uploaded);
  return {{"frames", setup_.frame_count},
          {"tracked", played_.tracked},
          {"lost", played_.lost},
          {"keyframes", slam_.keyFrameCount()},
          {"map_points", slam_.mapPointCount()},
          {"client_ms", toJson(played_.client_ms.summary())},
          {"e2e_ms", toJson(played_.e2e_ms.summary())},
          {"uplink_bytes", exchange.uplink_bytes},
          {"downlink_bytes", exchange.downlink_bytes},
          {"bytes_per_keyframe", exchange.uplink_bytes / keyframes_uploaded},
          {"keyframes_uploaded", exchange.keyframes_uploaded},
          {"uploads_dropped", exchange.uploads_dropped},
          {"uploads_overflowed", exchange.uploads_overflowed},
          {"uploads_unanswered", exchange.uploads_unanswered},
          {"keyframes_forgotten", exchange.keyframes_forgotten},
          {"points_forgotten", exchange.points_forgotten},
          {"slices_applied", exchange.slices_applied},
          {"reconnects", exchange.reconnects},
          {"slice_latency_ms", toJson(exchange.slice_latency_ms)},
          {"slice_apply_ms", toJson(exchange.slice_apply_ms)},
          {"segmentation_ms", toJson(counters_.semantic.segmentation_ms)},
          {"loops", counters_.map.loops},
          {"relocalizations", slam_.relocalizations()},
          {"tracking_recoveries", slam_.trackingRecoveries()},
          {"keyframe_decisions", keyFrameDecisionsJson(slam_.keyFrameDecisions())},
          {"map_resets", slam_.mapResets()},
          {"maps_started_at", slam_.mapsStartedAt()},
          {"map_merges", counters_.map.merges},
          {"maps_tied_back", mapsTiedBack(slam_.mapsStartedAt(), counters_.map.loop_frames)},
          {"tracked_in_discarded_maps", played_.tracked_in_discarded_maps},
          {"tracked_in_own_frames", ownFramesJson()},
          {"mode", options.mode},
          {"requested_mode", options.mode},
          {"sensor", setup_.sensor_name},
          {"dataset", setup_.info.path.string()},
          {"dataset_frames", frameRangeJson(options.frames, setup_.frame_count)},
          {"wall_s", wall_s_},
          {"pacing", options.realtime ? "realtime" : "fast"},
          {"deterministic", options.deterministic},
          {"localize_only", options.localize_only},
          {"frames_dropped_late", played_.frames_skipped_late},
          {"frames_skipped_late", played_.frames_skipped_late},
          {"frames_processed", played_.frame_log.size()},
          {"frames_read", played_.frames_read},
          {"frames_read_unused", played_.frames_read_unused},
          {"frames_out_of_order",
           {{"skipped", order.rejected()},
            {"duplicate_timestamp", order.duplicates()},
            {"timestamp_backwards", order.backwards()},
            {"timestamp_not_finite", order.notFinite()}}},
          {"backend_waits", backend.waits},
          {"backend_wait_ms",
           {{"total", backend.wait_total_ms},
            {"median", backend.wait_ms.median},
            {"p90", backend.wait_ms.p90},
            {"p95", backend.wait_ms.p95},
            {"p99", backend.wait_ms.p99},
            {"max", backend.wait_ms.max}}},
          {"backend_busy_refusals", backend.busy_refusals},
          {"keyframe_depth_ratio", counters_.map.keyframe_depth_ratio},
          {"warnings", warnings_},
          {"load_ms", toJson(played_.load_ms.summary())}};
}

void RunReport::addModeMetrics() {
  const RunOptions& options = setup_.options;
  nlohmann::json& metrics = metrics_;
  if (diagnostics_) {
    metrics["initialization"] = initializationJson(*diagnostics_);
    metrics["lost_frames"] = lostFramesJson(*diagnostics_);
  }
  if (options.localize_only) {
    // The frame (of this run) at which the first pose in the stored map was found.
    const auto& log = played_.frame_log;
    const auto first = std::find_if(log.begin(), log.end(), [](const auto& entry) {
      return entry.state == TrackingState::kOk;
    });
    metrics["localization"] = {
        {"map", options.map_name},
        {"stored_keyframes", slam_.keyFrameCount()},
        {"first_pose_frame", first == log.end() ? nlohmann::json() : nlohmann::json(first->index)}};
    const EdgeLocalizationCounters& edge = counters_.localization;
    if (edge.queries > 0) {
      // Through the edge: the questions the client asked and how they were answered.
      metrics["localization"]["edge"] = {{"queries", edge.queries},
                                         {"relocalization_queries", edge.relocalization_queries},
                                         {"relocalized_by_edge", edge.relocalized_by_edge},
                                         {"window_moves", edge.window_moves},
                                         {"answer_ms", toJson(edge.answer_ms)}};
    }
  }
  if (companions_.route) {
    metrics["navigation"] =
        companions_.route->json(played_.ground_truth, slam_.keyframeTrajectory(), at_time_, align_);
  }
  const ClientStageSummary& stages = counters_.stages;
  if (stages.features_ms.count > 0) {
    metrics["client_stages_ms"] = {{"features", toJson(stages.features_ms)},
                                   {"tracking", toJson(stages.tracking_ms)},
                                   {"keyframe", toJson(stages.keyframe_ms)}};
  }
  if (played_.compute_budget) metrics["compute_budget"] = computeBudgetJson();
  const EdgeExchangeCounters& exchange = counters_.exchange;
  if (const AdaptationLoop* adaptation = slam_.adaptation()) {
    metrics["adapt"] = adaptationJson(*adaptation);
    // Probes share the channel: keep them out of the per-keyframe figure.
    const std::uint64_t probe_bytes = adaptation->counters().probe_uplink_bytes;
    metrics["bytes_per_keyframe"] =
        (exchange.uplink_bytes - std::min<std::uint64_t>(exchange.uplink_bytes, probe_bytes)) /
        std::max<std::uint64_t>(1, exchange.keyframes_uploaded);
  }
  if (const std::optional<SplitClientReport> split = slam_.splitClientReport()) {
    addSplitClientMetrics(metrics, *split, counters_, options.client_map_keyframes);
  }
  if (options.semantic || companions_.semantic_eval) {
    const SemanticCounters& s = counters_.semantic;
    nlohmann::json semantic = {{"enabled", options.semantic},
                               {"keyframes_segmented", s.keyframes_segmented},
                               {"keyframes_not_segmented", s.keyframes_not_segmented},
                               {"movable_points_erased", s.movable_points_erased},
                               {"frames_with_mask", s.frames_with_mask},
                               {"features_culled", s.features_culled},
                               {"client_ms", toJson(s.client_ms)}};
    // Keyframes are segmented after they are tracked, so a tracked frame's mask is one transferred
    // from an earlier keyframe (or there is none yet); only the first frame of a map with depth
    // in local mode waits for its own (mask age 0).
    semantic["mask_source"] = {{"segmented_keyframes", s.keyframes_segmented},
                               {"transferred", s.frames_with_mask},
                               {"none", s.frames_without_mask}};
    semantic["mask_age_frames"] = maskAgeJson(s.mask_age);
    if (companions_.semantic_eval) semantic.update(companions_.semantic_eval->json());
    metrics["semantic"] = semantic;
  }
  if (ate_) metrics["ate"] = *ate_;
  if (companions_.pass_log) {
    metrics["repeat"] = options.repeat;
    metrics["passes"] = companions_.pass_log->json(played_.ground_truth, at_time_, align_);
  }
  if (ate_final_) metrics["ate_final"] = *ate_final_;
  if (!store_metrics_.is_null()) metrics["store"] = store_metrics_;
  if (companions_.viewer) metrics["viewer_port"] = companions_.viewer->port();
  if (refinement_) metrics["intrinsics_refinement"] = intrinsicsRefinementJson(*refinement_);
}

void RunReport::printSummary() const {
  const RunOptions& options = setup_.options;
  const std::size_t frame_count = setup_.frame_count;
  const PercentileSummary client = played_.client_ms.summary();
  fmt::print("\nSummary\n");
  fmt::print("  dataset      {} ({})\n", setup_.info.path.string(), toString(setup_.info.format));
  fmt::print("  mode/sensor  {} / {}\n", options.mode, setup_.sensor_name);
  fmt::print(
      "  frames       {} in {:.2f} s ({:.1f} fps), tracked {}, lost {}{}\n", frame_count, wall_s_,
      static_cast<double>(frame_count) / std::max(wall_s_, 1e-9), played_.tracked, played_.lost,
      played_.tracked_in_discarded_maps == 0 ? std::string()
                                             : fmt::format(" ({} more tracked in a discarded map)",
                                                           played_.tracked_in_discarded_maps));
  fmt::print(
      "  map          {} keyframes, {} points, {} relocalisations, {} recoveries, {} resets\n",
      slam_.keyFrameCount(), slam_.mapPointCount(), slam_.relocalizations(),
      slam_.trackingRecoveries(), slam_.mapResets());
  if (const std::vector<std::size_t> started = slam_.mapsStartedAt(); !started.empty()) {
    fmt::print(
        "  new maps     {} started after tracking was lost for good (at frames {}), {}\n",
        started.size(), fmt::join(started, ", "),
        options.mode == "local" || options.mode == "edge"
            ? fmt::format("{} tied back by a loop ({} by a merge of two parts)",
                          mapsTiedBack(started, counters_.map.loop_frames), counters_.map.merges)
            : std::string("merges in the edge's log"));
    const nlohmann::json own = ownFramesJson();
    if (own["at_frame_time"].get<std::size_t>() > 0) {
      fmt::print(
          "  own frames   {} tracked frames were in a new map's own frame at their time (in "
          "trajectory_map<k>.tum, not in trajectory.tum), {} of them in a map never merged (not "
          "in trajectory_final.tum either)\n",
          own["at_frame_time"].get<std::size_t>(), own["never_merged"].get<std::size_t>());
    }
  }
  if (diagnostics_ && diagnostics_->refusals != decltype(diagnostics_->refusals){}) {
    const std::string refused = refusalSummary(*diagnostics_);
    if (diagnostics_->initialized_at_frame) {
      fmt::print("  map start    frame {}, {} frames without a map (refused: {})\n",
                 *diagnostics_->initialized_at_frame, diagnostics_->frames_without_map, refused);
    } else {
      fmt::print("  map start    none (refused: {}; last: {})\n", refused,
                 diagnostics_->last_refusal);
    }
  }
  if (const std::optional<SplitClientReport> split = slam_.splitClientReport()) {
    const ClientMapSize& c = split->client_map;
    fmt::print("  client map   {} keyframes, {} points held (at most {} / {}; window {})\n",
               c.keyframes, c.points, c.max_keyframes, c.max_points,
               options.client_map_keyframes > 0 ? std::to_string(options.client_map_keyframes)
                                                : std::string("unbounded"));
  }
  const EdgeExchangeCounters& exchange = counters_.exchange;
  const EdgeLocalizationCounters& asked = counters_.localization;
  if (asked.queries > 0) {
    fmt::print(
        "  edge         {} questions ({} lost frames, {} relocalised by the edge; {} window "
        "moves), answered in median {:.1f} ms p95 {:.1f} ms, {} B up, {} B down\n",
        asked.queries, asked.relocalization_queries, asked.relocalized_by_edge, asked.window_moves,
        asked.answer_ms.median, asked.answer_ms.p95, exchange.uplink_bytes,
        exchange.downlink_bytes);
  } else if (options.mode != "local") {
    fmt::print(
        "  edge         {} keyframes up, {} slices back, slice latency median {:.1f} ms p90 "
        "{:.1f} ms, {} B up, {} B down\n",
        exchange.keyframes_uploaded, exchange.slices_applied, exchange.slice_latency_ms.median,
        exchange.slice_latency_ms.p90, exchange.uplink_bytes, exchange.downlink_bytes);
  }
  fmt::print("  client ms    median {:.2f}  p90 {:.2f}  p99 {:.2f}  max {:.2f}\n", client.median,
             client.p90, client.p99, client.max);
  const ClientStageSummary& stages = counters_.stages;
  if (stages.features_ms.count > 0) {
    fmt::print("  stages ms    features {:.2f}  tracking {:.2f}  keyframe {:.2f} (medians)\n",
               stages.features_ms.median, stages.tracking_ms.median, stages.keyframe_ms.median);
  }
  if (options.semantic) {
    const SemanticCounters& s = counters_.semantic;
    fmt::print(
        "  semantic     {} keyframes segmented ({:.0f} ms median), {} features culled, transfer "
        "and culling {:.2f} ms median per frame\n",
        s.keyframes_segmented, s.segmentation_ms.median, s.features_culled, s.client_ms.median);
  }
  if (companions_.semantic_eval) fmt::print("  {}\n", companions_.semantic_eval->summaryLine());
  if (ate_) {
    fmt::print("  ATE ({})    rmse {:.4f} m  ({} poses, at frame time)\n", toString(align_),
               (*ate_)["rmse_m"].get<double>(), (*ate_)["pairs"].get<std::size_t>());
  }
  if (companions_.pass_log) companions_.pass_log->print();
  if (ate_final_) {
    fmt::print("  ATE final    rmse {:.4f} m  ({} poses, refined)\n",
               (*ate_final_)["rmse_m"].get<double>(), (*ate_final_)["pairs"].get<std::size_t>());
  }
  if (companions_.route) printRouteSummary(metrics_["navigation"]);
  if (refinement_) fmt::print("  intrinsics   {}\n", describe(*refinement_));
  if (!store_metrics_.is_null() && store_metrics_.contains("bytes")) {
    fmt::print(
        "  map store    '{}' in {}: {} keyframes, {} points, {} B ({} B per keyframe), "
        "write median {:.1f} ms per batch\n",
        options.map_name, store_metrics_["location"].get<std::string>(),
        store_metrics_["keyframes"].get<std::uint64_t>(),
        store_metrics_["points"].get<std::uint64_t>(), store_metrics_["bytes"].get<std::uint64_t>(),
        store_metrics_["bytes_per_keyframe"].get<std::uint64_t>(),
        store_metrics_["write_ms"]["median"].get<double>());
  }
  if (played_.compute_budget) fmt::print("  compute      {}\n", computeBudgetLine());
  const BackendPacing& backend = counters_.backend;
  if (backend.waits > 0 || played_.frames_skipped_late > 0) {
    fmt::print(
        "  pacing       {}: waited for the back end {} times, {:.1f} s in all; {} frames "
        "skipped late (the camera had a newer one)\n",
        options.realtime ? "realtime" : "fast", backend.waits, backend.wait_total_ms / 1000.0,
        played_.frames_skipped_late);
  }
  for (const std::string& warning : warnings_) fmt::print("  WARNING      {}\n", warning);
}

namespace {

// The extraction frames actually had (the compute budget's steps, and Table I's pyramid in edge
// mode): the least features and levels, and the last frame's.
struct ExtractionSeen {
  int least_features = 0, least_levels = 0;
  int final_features = 0, final_levels = 0;
  std::size_t frames_reduced = 0;  // with fewer features than configured
};

ExtractionSeen extractionSeen(const std::vector<FrameLogEntry>& log, int configured_features) {
  ExtractionSeen seen;
  for (const FrameLogEntry& entry : log) {
    if (entry.features <= 0) continue;
    if (seen.least_features == 0 || entry.features < seen.least_features) {
      seen.least_features = entry.features;
    }
    if (seen.least_levels == 0 || entry.levels < seen.least_levels) {
      seen.least_levels = entry.levels;
    }
    seen.final_features = entry.features;
    seen.final_levels = entry.levels;
    if (entry.features < configured_features) ++seen.frames_reduced;
  }
  return seen;
}

}  // namespace

nlohmann::json RunReport::computeBudgetJson() const {
  const ComputeBudget& budget = *played_.compute_budget;
  const auto [features, levels] = played_.configured_extraction;
  const ExtractionSeen seen = extractionSeen(played_.frame_log, features);
  return {{"period_ms", budget.options().period_ms},
          {"frames_per_step", budget.framesPerStep()},
          {"switches", budget.switches()},
          {"deepest_step", budget.deepestStep()},
          {"final_step", budget.step()},
          {"frames_with_fewer_features", seen.frames_reduced},
          {"configured", {{"features", features}, {"levels", levels}}},
          {"least", {{"features", seen.least_features}, {"levels", seen.least_levels}}},
          {"final", {{"features", seen.final_features}, {"levels", seen.final_levels}}}};
}

std::string RunReport::computeBudgetLine() const {
  const ComputeBudget& budget = *played_.compute_budget;
  const auto [features, levels] = played_.configured_extraction;
  if (budget.deepestStep() == 0) {
    return fmt::format("frames fit the camera's period ({:.1f} ms): {} features kept",
                       budget.options().period_ms, features);
  }
  const ExtractionSeen seen = extractionSeen(played_.frame_log, features);
  return fmt::format(
      "fitted to the CPU ({:.1f} ms a frame): {} of {} frames with fewer features, at the least "
      "{} features and {} levels (configured {} and {}); {} switches, ending at {} and {}",
      budget.options().period_ms, seen.frames_reduced, played_.frame_log.size(),
      seen.least_features, seen.least_levels, features, levels, budget.switches(),
      seen.final_features, seen.final_levels);
}

void RunReport::writeOutputs() const {
  const std::filesystem::path& out_dir = setup_.options.out_dir;
  if (out_dir.empty()) return;
  std::filesystem::create_directories(out_dir);
  writeTumTrajectory(out_dir / "trajectory.tum", at_time_);
  writeTumTrajectory(out_dir / "trajectory_final.tum", final_);
  writeTumTrajectory(out_dir / "keyframes.tum", slam_.keyframeTrajectory());
  // A file of an earlier run in the same folder would pass for this run's.
  for (const auto& entry : std::filesystem::directory_iterator(out_dir)) {
    const std::string name = entry.path().filename().string();
    if (name.starts_with("trajectory_map") && name.ends_with(".tum")) {
      std::filesystem::remove(entry.path());
    }
  }
  for (const OwnMapTrajectory& own : own_frames_) {
    writeTumTrajectory(out_dir / fmt::format("trajectory_map{}.tum", own.map), own.poses);
  }
  // For `edgeslam report`: the dataset's poses at the frames the run read.
  if (!played_.ground_truth.empty()) {
    writeTumTrajectory(out_dir / "groundtruth.tum", played_.ground_truth);
  }
  writeFrameLog(out_dir / "frames.csv", played_.frame_log);
  if (companions_.route) companions_.route->writeInstructions(out_dir / "instructions.csv");
  std::ofstream out(out_dir / "metrics.json");
  out << metrics_.dump(2) << "\n";
  spdlog::info("wrote trajectories, frames.csv and metrics.json to {}", out_dir.string());
  if (refinement_) {
    if (const auto camera_file = writeRefinedCamera(out_dir, *refinement_); !camera_file.empty()) {
      spdlog::info("refined camera written to {} (--camera starts a run with it)",
                   camera_file.string());
    }
  }
}

}  // namespace edgeslam::cli
