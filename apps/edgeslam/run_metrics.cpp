#include "run_metrics.h"

#include <fmt/format.h>

#include "eval/ate.h"

namespace edgeslam::cli {

nlohmann::json toJson(const PercentileSummary& s) {
  return {{"median", s.median}, {"p90", s.p90}, {"p95", s.p95}, {"p99", s.p99}, {"max", s.max}};
}

nlohmann::json frameRangeJson(const std::optional<std::vector<FrameRange>>& ranges,
                              std::size_t played) {
  nlohmann::json out = {{"first", ranges ? ranges->front().first : 0}, {"count", played}};
  if (ranges && ranges->size() > 1) {
    nlohmann::json list = nlohmann::json::array();
    for (const FrameRange& r : *ranges) list.push_back({{"first", r.first}, {"last", r.last}});
    out["ranges"] = list;
  }
  return out;
}

nlohmann::json keyFrameDecisionsJson(const KeyFrameDecisionCounts& c) {
  return {{"rules", c.by_rules},
          {"forced", c.forced},
          {"starving", c.starving},
          {"segmentation", c.for_segmentation}};
}

std::optional<nlohmann::json> ateJson(const Trajectory& gt, const Trajectory& est,
                                      AlignMode align) {
  if (gt.empty() || est.size() < 3) return std::nullopt;
  const PosePairs pairs = associateByTimestamp(gt, est);
  if (pairs.size() < minimumPairsForAlignment(align)) return std::nullopt;
  const AteResult ate = computeAte(pairs, align);
  return nlohmann::json{{"rmse_m", ate.translation.rmse},
                        {"mean_m", ate.translation.mean},
                        {"median_m", ate.translation.median},
                        {"max_m", ate.translation.max},
                        {"pairs", ate.translation.count},
                        {"scale", ate.alignment.scale()},
                        {"align", toString(align)}};
}

nlohmann::json adaptationJson(const AdaptationLoop& loop) {
  const AdaptationLoopCounters c = loop.counters();
  const NetworkEstimates n = loop.estimates();
  const auto optional_json = [](const std::optional<double>& v) {
    return v ? nlohmann::json(*v) : nlohmann::json(nullptr);
  };
  return {{"enabled", loop.adapting()},
          {"switches", c.switches},
          {"frames_per_config", c.frames_per_config},
          {"probe_bytes", c.probe_bytes},
          {"failed_probes", c.failed_probes},
          {"unreachable_probes", c.unreachable_probes},
          {"latency_ms", optional_json(n.latency_ms)},
          {"bandwidth_mbps", optional_json(n.bandwidth_mbps)},
          {"network_time_ms", optional_json(n.network_time_ms)},
          {"message_bytes", n.message_bytes}};
}

void addSplitClientMetrics(nlohmann::json& metrics, const SplitClientReport& split,
                           const SlamCounters& counters, int client_map_window) {
  // The client's own map; keyframes / map_points above are the edge's global map.
  const ClientMapSize& c = split.client_map;
  metrics["client_map"] = {{"window_keyframes", client_map_window},
                           {"keyframes", c.keyframes},
                           {"points", c.points},
                           {"max_keyframes", c.max_keyframes},
                           {"max_points", c.max_points},
                           {"keyframes_evicted", c.keyframes_evicted},
                           {"keyframes_entered", c.keyframes_entered}};
  // Every keyframe the client made is on the edge, culled there as redundant, on its way, or
  // lost for a reason below.
  const ResyncCounters& r = split.resync;
  metrics["resync"] = {
      {"full_resyncs", r.full_resyncs},
      {"keyframes_made", counters.exchange.keyframes_uploaded - r.keyframes_resent},
      {"keyframes_resent", r.keyframes_resent},
      {"keyframes_culled_by_edge", r.keyframes_culled_by_edge},
      {"keyframes_lost",
       {{"upload_dropped", counters.exchange.keyframes_forgotten},
        {"evicted_before_stored", r.keyframes_lost_evicted}}}};
  const KeyFrameTriangulationStats& t = split.triangulation;
  if (t.keyframes > 0) {
    const PercentileSummary ms = t.ms.summary();
    metrics["client_triangulation"] = {
        {"keyframes", t.keyframes},
        {"points_created", t.points_created},
        {"ms_per_keyframe",
         {{"median", ms.median}, {"p90", ms.p90}, {"p95", ms.p95}, {"max", ms.max}}}};
  }
}

void printRouteSummary(const nlohmann::json& navigation) {
  fmt::print("  route        '{}': {} checkpoints, {} announced reached",
             navigation["route"].get<std::string>(), navigation["checkpoints"].get<std::size_t>(),
             navigation["reached_by_estimate"].get<std::size_t>());
  if (navigation.contains("success_rate")) {
    fmt::print(
        "; success {:.1f} % ({} within {:.2f} m of the truth; announced {:.2f} m from it, "
        "median)",
        100.0 * navigation["success_rate"].get<double>(), navigation["reached"].get<std::size_t>(),
        navigation["success_radius_m"].get<double>(),
        navigation["announced_error_m"]["median"].get<double>());
  }
  fmt::print("\n");
}

}  // namespace edgeslam::cli
