// `edgeslam run`: the whole pipeline (client and edge) in one command.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <optional>
#include <thread>

#include "commands.h"
#include "eval/ate.h"
#include "frame_log.h"
#include "intrinsics_report.h"
#include "io/camera_file.h"
#include "io/dataset.h"
#include "io/frame_order_guard.h"
#include "io/frame_range.h"
#include "io/live_camera.h"
#include "io/repeated_dataset.h"
#include "io/trajectory.h"
#include "link/link_settings.h"
#include "map_store_option.h"
#include "pipeline/edge_slam.h"
#include "pipeline/embedded_edge.h"
#include "pipeline/grpc_edge_link.h"
#include "pipeline/local_slam.h"
#include "pipeline/localization_slam.h"
#include "pipeline/offload_slam.h"
#include "pipeline/run_warnings.h"
#include "place/vocabulary.h"
#include "progress_line.h"
#include "repeat_passes.h"
#include "route_following.h"
#include "run_metrics.h"
#include "run_options.h"
#include "run_slam_options.h"
#include "run_viewer.h"
#include "segmenter_option.h"
#include "semantic_evaluation.h"
#include "store/store_location.h"
#include "store/stored_map_loader.h"
#include "tracking_diagnostics_json.h"
#include "util/timing_stats.h"
#include "viz/viewed_session_factory.h"
#include "vocabulary_option.h"

namespace edgeslam::cli {
namespace {

std::string resolveSensor(const std::string& requested, const DatasetInfo& info) {
  if (requested == "auto") return info.has_depth ? "rgbd" : "mono";
  if (requested == "rgbd" && !info.has_depth) {
    throw std::invalid_argument("--sensor rgbd needs depth images, and " + info.path.string() +
                                " has none");
  }
  if (requested == "stereo" && !info.has_stereo) {
    throw std::invalid_argument("--sensor stereo needs right images, and " + info.path.string() +
                                " has none");
  }
  return requested;
}

// Test hook (tests/pipeline/live_camera_command_test.cpp): EDGESLAM_TEST_EXTRA_LOAD_MS makes each
// paced frame read that much slower, a device too slow for its camera.
double testExtraLoadMs() {
  const char* value = std::getenv("EDGESLAM_TEST_EXTRA_LOAD_MS");
  if (value == nullptr) return 0.0;
  char* end = nullptr;
  const double ms = std::strtod(value, &end);
  return end != value && ms > 0.0 ? ms : 0.0;
}

Sensor toSensor(const std::string& name) {
  if (name == "rgbd") return Sensor::kRgbd;
  if (name == "stereo") return Sensor::kStereo;
  return Sensor::kMonocular;
}

// The edge the client talks to: a remote server (`client --server`), or one embedded in this
// process on loopback, behind the link emulator when a profile is asked for.
struct EdgeEndpoint {
  MapStoreChoice store;  // the embedded edge's; declared first, so the edge goes before it
  // The embedded edge's sessions, where the client does not hold the map (offload): their maps'
  // size per pass of --repeat.
  std::shared_ptr<viz::SessionDirectory> sessions;
  std::unique_ptr<EmbeddedEdge> embedded;
  std::string address;

  std::optional<EdgeMapSize> sessionMapSize() const {
    if (!sessions) return std::nullopt;
    for (const viz::SessionDirectory::Entry& entry : sessions->sessions()) {
      if (const auto backend = entry.backend.lock()) {
        const MapSample sample = backend->mapSample(0);
        return EdgeMapSize{sample.keyframe_poses.size(), sample.total_points};
      }
    }
    return std::nullopt;
  }
};

EdgeEndpoint openEdge(const RunOptions& options, const MappingBackendOptions& backend) {
  EdgeEndpoint edge;
  if (!options.server_address.empty()) {
    edge.address = options.server_address;
    if (options.link != "none") {
      spdlog::warn("--link applies to the embedded edge only; talking to {} directly",
                   edge.address);
    }
    if (!options.maps.empty()) {
      spdlog::warn("--maps applies to the embedded edge only; {} keeps maps in its own store",
                   edge.address);
    }
    return edge;
  }
  std::optional<LinkSettings> link;
  if (options.link != "none") link = linkProfile(options.link);
  SlamSessionOptions session;
  if (options.semantic)
    session.segmenter = segmenterOptions(options.models_dir, options.segment_input);
  // The edge session maps and closes loops as local mode would; its threads, their priority and
  // its segmenter stay the session's own.
  session.mapping.backend.mapper = backend.mapper;
  session.mapping.backend.vocabulary = backend.vocabulary;
  session.mapping.backend.loop_closing = backend.loop_closing;
  session.mapping.backend.loop_closer = backend.loop_closer;
  // Offload sessions keep no map yet: only edge mode opens the store.
  if (options.mode == "edge") edge.store = openStoreForWriting(options.maps);
  session.store = edge.store.store;
  session.store_stats = edge.store.stats;
  EmbeddedEdge::FactoryWrapper wrap;
  if (options.mode == "offload" && options.repeat > 1) {
    edge.sessions = std::make_shared<viz::SessionDirectory>();
    wrap = [directory = edge.sessions](std::shared_ptr<EdgeSessionFactory> inner) {
      return std::make_shared<viz::ViewedSessionFactory>(std::move(inner), directory);
    };
  }
  edge.embedded = std::make_unique<EmbeddedEdge>(session, link, wrap);
  edge.address = edge.embedded->clientAddress();
  spdlog::info("edge server on loopback, client connects to {}{}", edge.address,
               link ? " through link " + link->describe() : std::string());
  return edge;
}

SessionConfig sessionConfig(const PinholeCamera& camera, Sensor sensor,
                            const SlamOptions& slam_options, const RunOptions& options) {
  SessionConfig config;
  config.client_name = "edgeslam-client";
  config.map_name = options.map_name;
  config.camera = camera;
  config.sensor = sensor;
  config.settings.features = slam_options.orb.num_features;
  config.settings.pyramid_levels = slam_options.orb.num_levels;
  config.settings.scale_factor = slam_options.orb.scale_factor;
  config.settings.semantic = options.semantic;
  config.settings.client_map_keyframes = options.client_map_keyframes;
  return config;
}

// The stored map's latest session with keyframes, read from a store opened read-only.
std::unique_ptr<SlamSystem> makeLocalizationSlam(const RunOptions& options,
                                                 const PinholeCamera& camera,
                                                 const SlamOptions& slam_options) {
  const auto store = openMapStore(storeDirectory(options.maps), MapStoreAccess::kRead);
  std::optional<StoredMap> stored = store->loadMap(options.map_name);
  if (!stored) {
    throw std::runtime_error(
        fmt::format("--localize-only: no map '{}' in {}", options.map_name, store->location()));
  }
  const StoredSession* session = latestSessionWithKeyFrames(*stored);
  if (session == nullptr) {
    throw std::runtime_error(fmt::format("--localize-only: map '{}' in {} has no keyframes",
                                         options.map_name, store->location()));
  }
  try {
    return std::make_unique<LocalizationSlam>(camera, slam_options, *session);
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(
        fmt::format("--localize-only in map '{}': {}", options.map_name, e.what()));
  }
}

std::unique_ptr<SlamSystem> makeSlamSystem(const RunOptions& options, const std::string& mode,
                                           const PinholeCamera& camera, Sensor sensor,
                                           const SlamOptions& slam_options,
                                           const EdgeEndpoint& edge) {
  if (mode == "local" && options.localize_only) {
    return makeLocalizationSlam(options, camera, slam_options);
  }
  if (mode == "local") return std::make_unique<LocalSlam>(camera, slam_options);
  const SessionConfig config = sessionConfig(camera, sensor, slam_options, options);
  if (mode == "offload") {
    EdgeClientOptions offload_options;
    offload_options.credentials = loadClientCredentials(options.security);
    return std::make_unique<OffloadSlam>(
        sensor, std::make_unique<EdgeClient>(edge.address, config, offload_options));
  }
  EdgeClientOptions client_options;
  client_options.credentials = loadClientCredentials(options.security);
  client_options.keyframe_image.downscale = options.segment_reduce;
  client_options.omit_known_point_descriptors = options.omit_known_point_descriptors;
  // Room for the keyframes tracking makes while the edge is unreachable (EdgeKeyFrameSink's
  // max_in_flight_reconnecting); otherwise the sink's own bound keeps the queue short.
  client_options.upload_queue_capacity = 32;
  auto link = std::make_unique<GrpcEdgeLink>(edge.address, config, client_options);
  AdaptationLoopOptions adaptation;
  adaptation.adapt = options.adapt;
  adaptation.controller.initial_row = 0;  // the run starts with Table I row 1
  if (options.adapt &&
      (options.fmin || options.fmax || options.alpha || options.beta || options.levels)) {
    spdlog::warn(
        "--adapt on retunes fmin/fmax/alpha/beta/levels as the link changes; "
        "--adapt off keeps the values given");
  }
  return std::make_unique<EdgeSlam>(camera, slam_options, std::move(link), adaptation);
}

int runPipeline(const RunOptions& given) {
  RunOptions options = given;  // the map name may be chosen below
  // First, so that a port that cannot be served ends the run before anything is loaded.
  std::unique_ptr<RunViewer> viewer;
  if (options.viewer_port)
    viewer = std::make_unique<RunViewer>(options.viewer_host, *options.viewer_port);
  DatasetOptions dataset_options;
  dataset_options.format = parseDatasetFormat(options.format);
  if (options.camera_file) dataset_options.camera_override = loadCameraFile(*options.camera_file);
  auto reader = openDataset(options.dataset, dataset_options);
  if (options.frames) {
    try {
      reader = selectFrames(std::move(reader), *options.frames);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--frames", e.what());  // a usage error, known once the data is
    }
  }
  const std::size_t frames_per_pass = reader->info().frame_count;
  if (options.repeat > 1) reader = repeatFrames(std::move(reader), options.repeat);
  const DatasetInfo& info = reader->info();
  const std::string sensor_name = resolveSensor(options.sensor, info);
  if (sensor_name == "stereo") {
    throw std::invalid_argument("--sensor stereo is not supported yet; use mono or rgbd");
  }
  const Sensor sensor = toSensor(sensor_name);
  // Decode only what the run uses: colour is for segmenting keyframes, depth for RGB-D.
  reader->setContent({.color = options.semantic,
                      .depth = sensor == Sensor::kRgbd,
                      .right = sensor == Sensor::kStereo});
  const std::size_t frame_count =
      options.max_frames > 0 ? std::min(options.max_frames, info.frame_count) : info.frame_count;
  spdlog::info("dataset {} ({}, {} frames, {} fps), camera {}", info.path.string(),
               toString(info.format), info.frame_count, info.fps, reader->camera().describe());
  const std::string mode = options.mode;

  SlamOptions slam_options = slamOptionsForRun(options, reader->camera(), sensor);
  const KeyFrameParameters& kf = slam_options.tracker.keyframes;
  spdlog::info("{} ORB features, {} levels; keyframes fmin {} fmax {} alpha {} beta {}",
               slam_options.orb.num_features, slam_options.orb.num_levels, kf.fmin, kf.fmax,
               kf.alpha, kf.beta);
  if (mode == "local" && !options.localize_only && !options.maps.empty() &&
      options.maps != "none") {
    spdlog::warn("--maps: local runs keep no map yet (edge mode does)");
  }
  if (options.map_name.empty() && options.server_address.empty() && mode == "edge") {
    options.map_name = defaultMapName(
        info.path.filename().string().empty() ? std::string("run") : info.path.filename().string());
  }
  const EdgeEndpoint edge =
      mode == "local" ? EdgeEndpoint{} : openEdge(options, slam_options.backend);
  const std::unique_ptr<SlamSystem> slam_system =
      makeSlamSystem(options, mode, reader->camera(), sensor, slam_options, edge);
  SlamSystem& slam = *slam_system;
  const auto viewer_attachment = viewer ? viewer->attach(slam) : nullptr;
  viz::RunStatus view_status{.frames_total = frame_count,
                             .mode = mode,
                             .sensor = sensor_name,
                             .link = options.link,
                             .instruction = {}};
  // e2e: from the frame's arrival to its pose. With --realtime a frame arrives at its due time
  // on the camera clock (so reading it and any backlog count); otherwise when it has been read.
  SampleStats client_ms, load_ms, e2e_ms;
  std::vector<FrameLogEntry> frame_log;
  frame_log.reserve(frame_count);
  ProgressLine progress;
  Stopwatch wall;
  Trajectory ground_truth;
  std::size_t tracked = 0, lost = 0;
  std::size_t tracked_in_discarded_maps = 0, resets_seen = 0;
  FrameOrderGuard frame_order;
  std::optional<SemanticEvaluation> semantic_eval = SemanticEvaluation::open(info.path);
  if (semantic_eval) spdlog::info("ground-truth masks found: scoring the semantic culling");
  // Paced runs play the dataset as a live camera: a client that falls behind takes the newest
  // frame due and skips (never reads) the ones it was too busy for, so its latency stays bounded
  // under CPU starvation instead of growing with a queue of stale frames.
  std::optional<LiveCamera> live_camera;
  if (options.realtime) {
    live_camera.emplace(*reader, frame_count,
                        LiveCameraClock{.now_ms = [&wall] { return wall.elapsedMs(); },
                                        .sleep_ms = steadyLiveCameraClock().sleep_ms},
                        LiveCameraOptions{.extra_load_ms = testExtraLoadMs()});
  }
  const auto edge_map_size = [&edge] { return edge.sessionMapSize(); };
  std::optional<PassLog> pass_log;
  if (options.repeat > 1) pass_log.emplace(frames_per_pass);
  std::optional<RouteFollowing> route;
  if (!options.route.empty()) {
    route.emplace(
        storeDirectory(options.maps), options.map_name, options.route,
        RouteFollowingOptions{.success_radius_m = options.checkpoint_radius_m, .navigator = {}});
  }
  std::size_t next_unpaced = 0;
  for (;;) {
    std::size_t i = 0;
    DatasetFrame frame;
    double due_ms = 0.0;
    if (live_camera) {
      std::optional<LiveFrame> live = live_camera->grab();
      if (!live) break;
      i = live->index;
      due_ms = live->due_ms;
      load_ms.add(live->load_ms);
      frame = std::move(live->frame);
    } else {
      if (next_unpaced >= frame_count) break;
      i = next_unpaced++;
      Stopwatch load_timer;
      frame = reader->load(i);
      load_ms.add(load_timer.elapsedMs());
    }
    if (pass_log) pass_log->beforeFrame(i, slam, edge_map_size, wall.elapsedMs() / 1000.0);
    if (const auto rejection = frame_order.check(frame.timestamp)) {
      spdlog::warn("frame {} skipped: {} (t = {:.6f} s)", i, toString(*rejection), frame.timestamp);
      continue;
    }
    if (frame.ground_truth) ground_truth.push_back({frame.timestamp, *frame.ground_truth});
    Stopwatch frame_timer;
    const TrackResult result =
        slam.process(i, frame.timestamp, frame.gray, frame.depth, frame.color);
    const double processing_ms = frame_timer.elapsedMs();
    if (semantic_eval)
      semantic_eval->addFrame(i % frames_per_pass, result, slam.lastSemanticFrame());
    if (pass_log) pass_log->addFrame(i, frame.timestamp, result);
    if (route) {
      route->addFrame(i, frame.timestamp,
                      result.state == TrackingState::kOk ? result.T_cw : std::nullopt);
    }
    client_ms.add(processing_ms);
    double frame_e2e_ms = processing_ms;
    if (live_camera) frame_e2e_ms = std::max(processing_ms, wall.elapsedMs() - due_ms);
    e2e_ms.add(frame_e2e_ms);
    const ClientStageTimes stages = slam.lastFrameStages();
    frame_log.push_back({i, frame.timestamp, result.state, result.new_keyframe, result.relocalized,
                         result.tracked_points, load_ms.samples().back(), processing_ms,
                         frame_e2e_ms, stages.features_ms, stages.tracking_ms, stages.keyframe_ms});
    {
      FrameLogEntry& logged = frame_log.back();
      const LinkTraffic traffic = slam.linkTraffic();
      logged.uplink_bytes = traffic.uplink_bytes;
      logged.downlink_bytes = traffic.downlink_bytes;
      if (const AdaptationLoop* adaptation = slam.adaptation()) {
        logged.adaptation_row = static_cast<int>(adaptation->row());
      }
      if (const SemanticFrame* semantic = slam.lastSemanticFrame()) {
        logged.features_culled = semantic->culled;
      }
    }
    if (result.state == TrackingState::kOk) {
      ++tracked;
    } else if (result.state == TrackingState::kLost) {
      ++lost;
    }
    if (slam.mapResets() != resets_seen) {
      // A reset withdraws every pose of the map it discards: they leave `tracked`.
      resets_seen = slam.mapResets();
      tracked_in_discarded_maps += tracked;
      tracked = 0;
    }
    const double fps = static_cast<double>(i + 1) / std::max(1e-9, wall.elapsedMs() / 1000.0);
    const std::size_t keyframes = slam.keyFrameCount();
    const std::size_t map_points = slam.mapPointCount();
    progress.update(fmt::format("frame {}/{}  {:.1f} fps  {}  tracked {}  kf {}  points {}{}",
                                i + 1, frame_count, fps, toString(result.state), tracked, keyframes,
                                map_points, route ? "  " + route->lastText() : std::string()),
                    i + 1 == frame_count);
    if (viewer) {
      view_status.frame = i + 1;
      view_status.fps = fps;
      view_status.state = toString(result.state);
      view_status.tracked_points = result.tracked_points;
      view_status.keyframes = keyframes;
      view_status.map_points = map_points;
      view_status.client_ms = processing_ms;
      view_status.e2e_ms = frame_e2e_ms;
      view_status.adaptation_row = frame_log.back().adaptation_row;
      if (route) view_status.instruction = route->lastText();
      view_status.uplink_bytes = frame_log.back().uplink_bytes;
      view_status.downlink_bytes = frame_log.back().downlink_bytes;
      const std::optional<SE3d> camera =
          result.T_cw ? std::optional<SE3d>(result.T_cw->inverse()) : std::nullopt;
      viewer->view().publishFrame(view_status, camera, frame.ground_truth);
      viewer->publishImage(frame.color.empty() ? frame.gray : frame.color, result,
                           slam.lastSemanticFrame());
    }
  }
  progress.finish();
  if (pass_log) {
    pass_log->finish(slam, edge_map_size, wall.elapsedMs() / 1000.0);
  }
  slam.finish();
  // A live camera's skipped frames (kept under the older name too, which counted late drops).
  const std::size_t frames_skipped_late = live_camera ? live_camera->skipped() : 0;
  const std::size_t frames_dropped_late = frames_skipped_late;
  // What the edge's map store holds now (the last changes written first).
  const nlohmann::json store_metrics = storeMetrics(edge.store, options.map_name);
  const double seconds = wall.elapsedMs() / 1000.0;
  const PercentileSummary client = client_ms.summary();

  const Trajectory at_time = slam.trajectoryAtFrameTime();
  const Trajectory final_traj = slam.trajectoryFinal();
  const AlignMode align = sensor == Sensor::kMonocular ? AlignMode::kSim3 : AlignMode::kSe3;
  const auto ate = ateJson(ground_truth, at_time, align);
  const auto ate_final = ateJson(ground_truth, final_traj, align);

  const SlamCounters counters = slam.counters();
  const std::optional<TrackingDiagnostics> diagnostics = slam.trackingDiagnostics();
  std::vector<std::string> warnings =
      runWarnings({.frames = frame_count,
                   .tracked = tracked,
                   .lost = lost,
                   .frames_dropped_late = frames_dropped_late,
                   .backend_busy_refusals = counters.backend.busy_refusals,
                   .backend_wait_ms = counters.backend.wait_total_ms,
                   .wall_ms = seconds * 1000.0,
                   .monocular = sensor == Sensor::kMonocular,
                   .keyframe_depth_ratio = counters.keyframe_depth_ratio,
                   .frames_out_of_order = frame_order.rejected(),
                   .frames_without_map = diagnostics ? diagnostics->frames_without_map : 0,
                   .map_built = !diagnostics || diagnostics->initialized_at_frame.has_value() ||
                                options.localize_only,
                   .refusals = diagnostics ? refusalSummary(*diagnostics) : std::string()});
  if (std::string store_warning = storeWarning(store_metrics, slam.keyFrameCount());
      !store_warning.empty()) {
    warnings.push_back(std::move(store_warning));
  }
  const std::size_t keyframes_uploaded = std::max<std::size_t>(1, counters.keyframes_uploaded);
  nlohmann::json metrics = {{"frames", frame_count},
                            {"tracked", tracked},
                            {"lost", lost},
                            {"keyframes", slam.keyFrameCount()},
                            {"map_points", slam.mapPointCount()},
                            {"client_ms", toJson(client)},
                            {"e2e_ms", toJson(e2e_ms.summary())},
                            {"uplink_bytes", counters.uplink_bytes},
                            {"downlink_bytes", counters.downlink_bytes},
                            {"bytes_per_keyframe", counters.uplink_bytes / keyframes_uploaded},
                            {"keyframes_uploaded", counters.keyframes_uploaded},
                            {"uploads_dropped", counters.uploads_dropped},
                            {"uploads_overflowed", counters.uploads_overflowed},
                            {"uploads_unanswered", counters.uploads_unanswered},
                            {"keyframes_forgotten", counters.keyframes_forgotten},
                            {"points_forgotten", counters.points_forgotten},
                            {"slices_applied", counters.slices_applied},
                            {"reconnects", counters.reconnects},
                            {"slice_latency_ms", toJson(counters.slice_latency_ms)},
                            {"slice_apply_ms", toJson(counters.slice_apply_ms)},
                            {"segmentation_ms", toJson(counters.segmentation_ms)},
                            {"loops", counters.loops},
                            {"relocalizations", slam.relocalizations()},
                            {"tracking_recoveries", slam.trackingRecoveries()},
                            {"keyframe_decisions", keyFrameDecisionsJson(slam.keyFrameDecisions())},
                            {"map_resets", slam.mapResets()},
                            {"tracked_in_discarded_maps", tracked_in_discarded_maps},
                            {"mode", mode},
                            {"requested_mode", options.mode},
                            {"sensor", sensor_name},
                            {"dataset", info.path.string()},
                            {"dataset_frames", frameRangeJson(options.frames, frame_count)},
                            {"wall_s", seconds},
                            {"pacing", options.realtime ? "realtime" : "fast"},
                            {"deterministic", options.deterministic},
                            {"localize_only", options.localize_only},
                            {"frames_dropped_late", frames_dropped_late},
                            {"frames_skipped_late", frames_skipped_late},
                            {"frames_processed", frame_log.size()},
                            {"frames_read", live_camera ? live_camera->reads() : frame_count},
                            {"frames_read_unused", live_camera ? live_camera->unusedReads() : 0},
                            {"frames_out_of_order",
                             {{"skipped", frame_order.rejected()},
                              {"duplicate_timestamp", frame_order.duplicates()},
                              {"timestamp_backwards", frame_order.backwards()},
                              {"timestamp_not_finite", frame_order.notFinite()}}},
                            {"backend_waits", counters.backend.waits},
                            {"backend_wait_ms",
                             {{"total", counters.backend.wait_total_ms},
                              {"median", counters.backend.wait_ms.median},
                              {"p90", counters.backend.wait_ms.p90},
                              {"p95", counters.backend.wait_ms.p95},
                              {"p99", counters.backend.wait_ms.p99},
                              {"max", counters.backend.wait_ms.max}}},
                            {"backend_busy_refusals", counters.backend.busy_refusals},
                            {"keyframe_depth_ratio", counters.keyframe_depth_ratio},
                            {"warnings", warnings},
                            {"load_ms", toJson(load_ms.summary())}};
  if (diagnostics) {
    metrics["initialization"] = initializationJson(*diagnostics);
    metrics["lost_frames"] = lostFramesJson(*diagnostics);
  }
  if (options.localize_only) {
    // The frame (of this run) at which the first pose in the stored map was found.
    const auto first = std::find_if(frame_log.begin(), frame_log.end(), [](const auto& entry) {
      return entry.state == TrackingState::kOk;
    });
    metrics["localization"] = {
        {"map", options.map_name},
        {"stored_keyframes", slam.keyFrameCount()},
        {"first_pose_frame",
         first == frame_log.end() ? nlohmann::json() : nlohmann::json(first->index)}};
  }
  if (route) {
    metrics["navigation"] = route->json(ground_truth, slam.keyframeTrajectory(), at_time, align);
  }
  if (counters.features_ms.count > 0) {
    metrics["client_stages_ms"] = {{"features", toJson(counters.features_ms)},
                                   {"tracking", toJson(counters.tracking_ms)},
                                   {"keyframe", toJson(counters.keyframe_ms)}};
  }
  if (const AdaptationLoop* adaptation = slam.adaptation()) {
    metrics["adapt"] = adaptationJson(*adaptation);
    // Probes share the channel: keep them out of the per-keyframe figure.
    const std::uint64_t probe_bytes = adaptation->counters().probe_uplink_bytes;
    metrics["bytes_per_keyframe"] =
        (counters.uplink_bytes - std::min<std::uint64_t>(counters.uplink_bytes, probe_bytes)) /
        keyframes_uploaded;
  }
  if (const std::optional<SplitClientReport> split = slam.splitClientReport()) {
    addSplitClientMetrics(metrics, *split, counters, options.client_map_keyframes);
  }
  if (options.semantic || semantic_eval) {
    nlohmann::json semantic = {{"enabled", options.semantic},
                               {"keyframes_segmented", counters.keyframes_segmented},
                               {"movable_points_erased", counters.movable_points_erased},
                               {"frames_with_mask", counters.frames_with_mask},
                               {"features_culled", counters.features_culled},
                               {"client_ms", toJson(counters.semantic_client_ms)}};
    if (semantic_eval) semantic.update(semantic_eval->json());
    metrics["semantic"] = semantic;
  }
  if (ate) metrics["ate"] = *ate;
  if (pass_log) {
    metrics["repeat"] = options.repeat;
    metrics["passes"] = pass_log->json(ground_truth, at_time, align);
  }
  if (ate_final) metrics["ate_final"] = *ate_final;
  if (!store_metrics.is_null()) metrics["store"] = store_metrics;
  if (viewer) metrics["viewer_port"] = viewer->port();
  const std::optional<MapIntrinsicsRefinement> refinement = slam.intrinsicsRefinement();
  if (refinement) metrics["intrinsics_refinement"] = intrinsicsRefinementJson(*refinement);

  fmt::print("\nSummary\n");
  fmt::print("  dataset      {} ({})\n", info.path.string(), toString(info.format));
  fmt::print("  mode/sensor  {} / {}\n", mode, sensor_name);
  fmt::print("  frames       {} in {:.2f} s ({:.1f} fps), tracked {}, lost {}{}\n", frame_count,
             seconds, static_cast<double>(frame_count) / std::max(seconds, 1e-9), tracked, lost,
             tracked_in_discarded_maps == 0
                 ? std::string()
                 : fmt::format(" ({} more tracked in a discarded map)", tracked_in_discarded_maps));
  fmt::print(
      "  map          {} keyframes, {} points, {} relocalisations, {} recoveries, {} resets\n",
      slam.keyFrameCount(), slam.mapPointCount(), slam.relocalizations(), slam.trackingRecoveries(),
      slam.mapResets());
  if (diagnostics && diagnostics->refusals != decltype(diagnostics->refusals){}) {
    const std::string refused = refusalSummary(*diagnostics);
    if (diagnostics->initialized_at_frame) {
      fmt::print("  map start    frame {}, {} frames without a map (refused: {})\n",
                 *diagnostics->initialized_at_frame, diagnostics->frames_without_map, refused);
    } else {
      fmt::print("  map start    none (refused: {}; last: {})\n", refused,
                 diagnostics->last_refusal);
    }
  }
  if (const std::optional<SplitClientReport> split = slam.splitClientReport()) {
    const ClientMapSize& c = split->client_map;
    fmt::print("  client map   {} keyframes, {} points held (at most {} / {}; window {})\n",
               c.keyframes, c.points, c.max_keyframes, c.max_points,
               options.client_map_keyframes > 0 ? std::to_string(options.client_map_keyframes)
                                                : std::string("unbounded"));
  }
  if (mode != "local") {
    fmt::print(
        "  edge         {} keyframes up, {} slices back, slice latency median {:.1f} ms p90 "
        "{:.1f} ms, {} B up, {} B down\n",
        counters.keyframes_uploaded, counters.slices_applied, counters.slice_latency_ms.median,
        counters.slice_latency_ms.p90, counters.uplink_bytes, counters.downlink_bytes);
  }
  fmt::print("  client ms    median {:.2f}  p90 {:.2f}  p99 {:.2f}  max {:.2f}\n", client.median,
             client.p90, client.p99, client.max);
  if (counters.features_ms.count > 0) {
    fmt::print("  stages ms    features {:.2f}  tracking {:.2f}  keyframe {:.2f} (medians)\n",
               counters.features_ms.median, counters.tracking_ms.median,
               counters.keyframe_ms.median);
  }
  if (options.semantic) {
    fmt::print(
        "  semantic     {} keyframes segmented ({:.0f} ms median), {} features culled, transfer "
        "and culling {:.2f} ms median per frame\n",
        counters.keyframes_segmented, counters.segmentation_ms.median, counters.features_culled,
        counters.semantic_client_ms.median);
  }
  if (semantic_eval) fmt::print("  {}\n", semantic_eval->summaryLine());
  if (ate) {
    fmt::print("  ATE ({})    rmse {:.4f} m  ({} poses, at frame time)\n", toString(align),
               (*ate)["rmse_m"].get<double>(), (*ate)["pairs"].get<std::size_t>());
  }
  if (pass_log) pass_log->print();
  if (ate_final) {
    fmt::print("  ATE final    rmse {:.4f} m  ({} poses, refined)\n",
               (*ate_final)["rmse_m"].get<double>(), (*ate_final)["pairs"].get<std::size_t>());
  }
  if (route) printRouteSummary(metrics["navigation"]);
  if (refinement) fmt::print("  intrinsics   {}\n", describe(*refinement));
  if (!store_metrics.is_null() && store_metrics.contains("bytes")) {
    fmt::print(
        "  map store    '{}' in {}: {} keyframes, {} points, {} B ({} B per keyframe), "
        "write median {:.1f} ms per batch\n",
        options.map_name, store_metrics["location"].get<std::string>(),
        store_metrics["keyframes"].get<std::uint64_t>(),
        store_metrics["points"].get<std::uint64_t>(), store_metrics["bytes"].get<std::uint64_t>(),
        store_metrics["bytes_per_keyframe"].get<std::uint64_t>(),
        store_metrics["write_ms"]["median"].get<double>());
  }
  if (counters.backend.waits > 0 || frames_dropped_late > 0) {
    fmt::print(
        "  pacing       {}: waited for the back end {} times, {:.1f} s in all; {} frames "
        "skipped late (the camera had a newer one)\n",
        options.realtime ? "realtime" : "fast", counters.backend.waits,
        counters.backend.wait_total_ms / 1000.0, frames_dropped_late);
  }
  for (const std::string& warning : warnings) fmt::print("  WARNING      {}\n", warning);

  if (!options.out_dir.empty()) {
    std::filesystem::create_directories(options.out_dir);
    writeTumTrajectory(options.out_dir / "trajectory.tum", at_time);
    writeTumTrajectory(options.out_dir / "trajectory_final.tum", final_traj);
    writeTumTrajectory(options.out_dir / "keyframes.tum", slam.keyframeTrajectory());
    // For `edgeslam report`: the dataset's poses at the frames the run read.
    if (!ground_truth.empty())
      writeTumTrajectory(options.out_dir / "groundtruth.tum", ground_truth);
    writeFrameLog(options.out_dir / "frames.csv", frame_log);
    if (route) route->writeInstructions(options.out_dir / "instructions.csv");
    std::ofstream out(options.out_dir / "metrics.json");
    out << metrics.dump(2) << "\n";
    spdlog::info("wrote trajectories, frames.csv and metrics.json to {}", options.out_dir.string());
    if (refinement) {
      if (const auto camera_file = writeRefinedCamera(options.out_dir, *refinement);
          !camera_file.empty()) {
        spdlog::info("refined camera written to {} (--camera starts a run with it)",
                     camera_file.string());
      }
    }
  }
  if (viewer) viewer->finish(options.viewer_linger_s);
  return 0;
}

}  // namespace

void addRunOptions(CLI::App* run, const std::shared_ptr<RunOptions>& options) {
  run->add_option("--dataset", options->dataset, "Dataset folder (or video file)")->required();
  run->add_option("--format", options->format, "Dataset format")
      ->check(CLI::IsMember({"auto", "tum", "kitti", "euroc", "7scenes", "images", "video"}));
  run->add_option("--sensor", options->sensor, "Sensor; auto = rgbd when the dataset has depth")
      ->check(CLI::IsMember({"auto", "mono", "rgbd", "stereo"}));
  run->add_option("--mode", options->mode, "edge (edgeSLAM), local (ORB-SLAM), offload (Mask-SLAM)")
      ->check(CLI::IsMember({"edge", "local", "offload"}));
  run->add_option("--link", options->link,
                  "Emulated link between client and edge: none, wifi5, wifi24, lte, lte-congested")
      ->check(CLI::IsMember(linkProfileNames()));
  run->add_option("--adapt", options->adapt, "Self-adaptation on|off")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}));
  run->add_option("--semantic", options->semantic,
                  "Semantic culling on|off (default off): keyframes segmented, people culled")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}));
  run->add_option("--models", options->models_dir,
                  "Segmentation models folder for --semantic on (default: the shared models)");
  run->add_option("--segment-input", options->segment_input,
                  "Side of the segmentation detector's input (multiple of 32)")
      ->capture_default_str();
  run->add_option("--segment-reduce", options->segment_reduce,
                  "Keyframes are segmented at 1/N of full size (the image sent to the edge)")
      ->check(CLI::Range(1, 8))
      ->capture_default_str();
  run->add_option("--segment-refresh", options->segment_refresh,
                  "With semantic culling, a keyframe (and so a segmentation) at least every N "
                  "frames of a 30 fps camera, so that people walking into view are masked soon "
                  "(0 = keyframes by the usual rules only)")
      ->check(CLI::Range(0, 1000))
      ->capture_default_str();
  run->add_option("--segment-refresh-min", options->segment_refresh_min,
                  "The refresh interval shortens to 4x the masks' delay in frames, down to N "
                  "(default: " +
                      std::to_string(SegmentationRefreshOptions{}.min_frames) +
                      "; equal to --segment-refresh: a fixed interval)")
      ->check(CLI::Range(1, 1000));
  run->add_option("--recover-frames", options->recover_frames,
                  "After tracking fails, for up to N frames the camera is assumed to keep its "
                  "velocity and is searched for there before relocalisation (0 = off)")
      ->check(CLI::Range(0, 300))
      ->capture_default_str();
  auto* max_frames =
      run->add_option("--max-frames", options->max_frames, "Process at most N frames (0 = all)");
  run->add_option("--repeat", options->repeat,
                  "Play the frames N times in a row into one map (the camera jumps back to the "
                  "first frame at each pass); metrics.json \"passes\" has each pass's figures")
      ->check(CLI::Range(1, 1000))
      ->excludes(max_frames)
      ->capture_default_str();
  run->add_option_function<std::string>(
         "--frames",
         [options](const std::string& text) { options->frames = parseFrameRange(text); },
         "Play only frames A-B of the dataset (0-based, inclusive), as if they were the whole "
         "sequence: one recording standing in for several sessions")
      ->type_name("A-B")
      ->check([](const std::string& text) {
        try {
          (void)parseFrameRange(text);
          return std::string();
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
      });
  addMapsOption(run, options->maps);
  run->add_option("--map", options->map_name,
                  "Edge map this session writes into (created when new; default: a new map named "
                  "after the dataset and time)")
      ->check([](const std::string& name) {
        try {
          checkMapName(name);
          return std::string();
        } catch (const std::invalid_argument& e) {
          return std::string(e.what());
        }
      });
  auto* realtime = run->add_flag("--realtime", options->realtime,
                                 "Feed frames at the dataset's rate, dropping none");
  run->add_flag("--fast", options->fast, "Feed frames as fast as possible (the default)")
      ->excludes(realtime);
  run->add_flag("--deterministic", options->deterministic,
                "Local mode: map each keyframe (and close loops) before the next frame, on one "
                "thread, so two runs give the same trajectory (for tests and bisecting; slower)")
      ->excludes(realtime);
  run->add_flag("--localize-only", options->localize_only,
                "Local mode: localise in the stored map --map (from --maps) and follow it; no "
                "keyframe is made and the store is opened read-only");
  run->add_option("--route", options->route,
                  "With --localize-only: follow this route of the map (`edgeslam route make`): an "
                  "instruction every frame (instructions.csv, progress line, viewer) and the "
                  "checkpoint success rate in metrics.json");
  run->add_option("--checkpoint-radius", options->checkpoint_radius_m,
                  "With --route: a checkpoint succeeds when announced while the true position is "
                  "within this many metres of it")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  run->add_option("--out", options->out_dir,
                  "Output folder (trajectories, metrics.json, frames.csv with each frame's times)");
  run->add_option("--viewer", options->viewer_port,
                  "Serve the live web viewer on this port (0 = any free port; the URL is logged)")
      ->check(CLI::Range(0, 65535));
  run->add_option("--viewer-host", options->viewer_host,
                  "Address the viewer listens on (0.0.0.0 = every interface)")
      ->capture_default_str();
  run->add_option("--viewer-linger", options->viewer_linger_s,
                  "Keep the viewer up on the final map this many seconds after the run (Ctrl-C "
                  "stops it)")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  run->add_option("--camera", options->camera_file, "Camera YAML overriding the dataset's camera")
      ->check(CLI::ExistingFile);
  run->add_option("--vocab", options->vocabulary,
                  "Vocabulary file for relocalisation and loops (default: vocab/ next to the "
                  "binary or $EDGESLAM_VOCAB; none = without)");
  run->add_option("--client-map-keyframes", options->client_map_keyframes,
                  "Edge mode: the client keeps features and points of about N keyframes around "
                  "its latest one (the edge picks them, evicting the rest; relocalisation then "
                  "searches these only); 0 = the whole map")
      ->check(CLI::Range(0, 100000))
      ->capture_default_str();
  run->add_option("--loops", options->loop_closing, "Loop closing on|off (needs a vocabulary)")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}));
  run->add_option("--client-triangulation", options->client_triangulation,
                  "Edge mode, monocular: the client triangulates new points with its neighbour "
                  "keyframes at each keyframe, so tracking need not wait for the edge's points "
                  "(on|off, default on)")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}));
  run->add_option(
         "--features", options->features,
         "ORB features per frame (default 1000, 2000 above 640x480; edge mode at most 1600, "
         "which keeps a keyframe upload within about 60 KB)")
      ->check(CLI::Range(100, 20000));
  run->add_option("--levels", options->levels, "ORB pyramid levels (Table I nl)")
      ->check(CLI::Range(1, 12));
  run->add_option("--fmin", options->fmin, "Keyframe rule 1: frames since the last keyframe")
      ->check(CLI::Range(0, 1000));
  run->add_option("--fmax", options->fmax, "Keyframe rule 2: frames since the last map update")
      ->check(CLI::Range(1, 1000));
  run->add_option("--alpha", options->alpha, "Keyframe rule 3: feature ratio to the reference")
      ->check(CLI::Range(0.0, 1.0));
  run->add_option("--beta", options->beta, "Keyframe rule 4: tracked ratio to the reference")
      ->check(CLI::Range(0.0, 1.0));
  run->add_option("--starving", options->starving,
                  "Tracked ratio below which keyframe rule 1 is waived (tracking starves)")
      ->check(CLI::Range(0.0, 1.0));
  run->add_option("--refine-intrinsics", options->refine_intrinsics,
                  "Local mode: at the end of the run, a self-calibrating bundle adjustment "
                  "refines these intrinsics from the map (off, or a set of focal, k1, k2) and "
                  "re-solves the map with them where that lowers the reprojection error; "
                  "camera_refined.yaml is written beside the trajectories")
      ->check(CLI::Validator(
          [](std::string& value) {
            return parseRefinedIntrinsics(value)
                       ? std::string()
                       : "expected off or a comma-separated set of focal, k1, k2, got '" + value +
                             "'";
          },
          "off|focal,k1,k2", "intrinsics set"))
      ->default_str("focal,k1")
      ->group("Advanced");
  run->add_option("--triangulation-search", options->triangulation_search,
                  "Local mapping's new-point search: bow (direct index, needs a vocabulary) or "
                  "band (whole epipolar band); default bow")
      ->check(CLI::IsMember({"bow", "band"}))
      ->group("Advanced");
  run->add_option("--upload-descriptors", options->omit_known_point_descriptors,
                  "Edge mode: descriptors a keyframe upload carries: new (leave out those of "
                  "keypoints whose point the edge has; it substitutes the point's) or all")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, bool>{{"new", true}, {"all", false}}))
      ->group("Advanced");
}

void addRunCommand(CLI::App& app) {
  auto options = std::make_shared<RunOptions>();
  auto* run = app.add_subcommand("run", "Run SLAM on a dataset (client and edge in one command)");
  addRunOptions(run, options);
  run->callback([options] { exitCode() = runPipeline(*options); });
}

void addClientCommand(CLI::App& app) {
  auto options = std::make_shared<RunOptions>();
  auto* client = app.add_subcommand(
      "client", "The mobile client alone, against an edge server (`edgeslam server`)");
  addRunOptions(client, options);
  client->add_option("--server", options->server_address, "Edge server HOST:PORT")->required();
  addClientSecurityOptions(*client, options->security);
  client->callback([options] {
    if (options->mode == "local") {
      throw CLI::ValidationError("--mode", "edgeslam client needs --mode edge or offload");
    }
    exitCode() = runPipeline(*options);
  });
}

const CommandRegistration kClientCommandRegistration{20, addClientCommand};

const CommandRegistration kRunCommandRegistration{10, addRunCommand};

}  // namespace edgeslam::cli
