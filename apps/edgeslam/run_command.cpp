// `edgeslam run`: the whole pipeline (client and edge) in one command.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <opencv2/core/utility.hpp>
#include <optional>
#include <thread>

#include "commands.h"
#include "io/camera_file.h"
#include "io/dataset.h"
#include "io/frame_range.h"
#include "io/preloaded_dataset.h"
#include "io/repeated_dataset.h"
#include "linkem/link_settings.h"
#include "map_store_option.h"
#include "modes/edge_localization_slam.h"
#include "modes/edge_slam.h"
#include "modes/embedded_edge.h"
#include "modes/grpc_edge_link.h"
#include "modes/local_slam.h"
#include "modes/localization_slam.h"
#include "modes/offload_slam.h"
#include "place/vocabulary.h"
#include "progress_line.h"
#include "repeat_passes.h"
#include "route_following.h"
#include "run_frame_loop.h"
#include "run_options.h"
#include "run_report.h"
#include "run_slam_options.h"
#include "run_viewer.h"
#include "segmenter_option.h"
#include "semantic_evaluation.h"
#include "store/store_location.h"
#include "store/stored_map_loader.h"
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
  // Offload sessions keep no map yet: only edge mode opens the store. A localise-only session
  // only reads it.
  if (options.mode == "edge" && options.localize_only) {
    edge.store.store = openMapStore(storeDirectory(options.maps), MapStoreAccess::kRead);
  } else if (options.mode == "edge") {
    edge.store = openStoreForWriting(options.maps);
  }
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
  config.settings.localize_only = options.localize_only;
  config.settings.frames_back_to_back = slam_options.wait_for_backend;
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
  if (options.localize_only) {
    return std::make_unique<EdgeLocalizationSlam>(camera, slam_options, std::move(link));
  }
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

// The dataset as the run plays it: the frames selected, repeated, and decoded for the sensor.
struct RunInput {
  std::unique_ptr<DatasetReader> reader;
  std::size_t frames_per_pass = 0;
  std::size_t frame_count = 0;  // to play
  std::string sensor_name;
  Sensor sensor = Sensor::kMonocular;
};

RunInput openRunInput(const RunOptions& options) {
  RunInput input;
  DatasetOptions dataset_options;
  dataset_options.format = parseDatasetFormat(options.format);
  if (options.camera_file) dataset_options.camera_override = loadCameraFile(*options.camera_file);
  input.reader = openDataset(options.dataset, dataset_options);
  if (options.frames) {
    try {
      input.reader = selectFrames(std::move(input.reader), *options.frames);
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--frames", e.what());  // a usage error, known once the data is
    }
  }
  input.frames_per_pass = input.reader->info().frame_count;
  if (options.repeat > 1) input.reader = repeatFrames(std::move(input.reader), options.repeat);
  const DatasetInfo& info = input.reader->info();
  input.sensor_name = resolveSensor(options.sensor, info);
  if (input.sensor_name == "stereo") {
    throw std::invalid_argument("--sensor stereo is not supported yet; use mono or rgbd");
  }
  input.sensor = toSensor(input.sensor_name);
  // Decode only what the run uses: colour is for segmenting keyframes, depth for RGB-D.
  input.reader->setContent({.color = options.semantic,
                            .depth = input.sensor == Sensor::kRgbd,
                            .right = input.sensor == Sensor::kStereo});
  input.frame_count =
      options.max_frames > 0 ? std::min(options.max_frames, info.frame_count) : info.frame_count;
  if (options.preload) {
    ProgressLine progress;
    const std::size_t count = input.frame_count;
    input.reader = preloadFrames(std::move(input.reader), count, [&](std::size_t done) {
      progress.update(fmt::format("preloading frame {}/{}", done, count), done == count);
    });
    progress.finish();
  }
  spdlog::info("dataset {} ({}, {} frames, {} fps), camera {}", info.path.string(),
               toString(info.format), info.frame_count, info.fps,
               input.reader->camera().describe());
  return input;
}

// The client's cost fitted to its CPU: at the camera's pace only (`--fast` has no deadline), and
// where the client extracts features (not offload).
std::optional<ComputeBudgetOptions> computeBudgetFor(const RunOptions& options,
                                                     const std::string& mode,
                                                     const PinholeCamera& camera) {
  if (!options.realtime || !options.compute_adapt || mode == "offload") return std::nullopt;
  const double fps = camera.intrinsics().fps > 0.0 ? camera.intrinsics().fps : 30.0;
  if (options.features || options.levels) {
    spdlog::info(
        "--compute-adapt on: --features and --levels are where the client starts; it lowers them "
        "when frames do not fit the camera's period (--compute-adapt off keeps them)");
  }
  ComputeBudgetOptions budget;
  budget.period_ms = 1000.0 / fps;
  return budget;
}

// The run: the dataset, the mode's SLAM system (with its edge), the frames played through it with
// their companions, and the report.
int runPipeline(const RunOptions& given) {
  RunOptions options = given;  // the map name may be chosen below
  // First, so that a port that cannot be served ends the run before anything is loaded.
  std::unique_ptr<RunViewer> viewer;
  if (options.viewer_port)
    viewer = std::make_unique<RunViewer>(options.viewer_host, *options.viewer_port);
  RunInput input = openRunInput(options);
  const DatasetInfo& info = input.reader->info();
  const std::string& mode = options.mode;

  SlamOptions slam_options = slamOptionsForRun(options, input.reader->camera(), input.sensor);
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
      makeSlamSystem(options, mode, input.reader->camera(), input.sensor, slam_options, edge);
  SlamSystem& slam = *slam_system;
  const auto viewer_attachment = viewer ? viewer->attach(slam) : nullptr;

  std::optional<SemanticEvaluation> semantic_eval = SemanticEvaluation::open(info.path);
  if (semantic_eval) spdlog::info("ground-truth masks found: scoring the semantic culling");
  std::optional<PassLog> pass_log;
  if (options.repeat > 1) pass_log.emplace(input.frames_per_pass);
  std::optional<RouteFollowing> route;
  if (!options.route.empty()) {
    route.emplace(
        storeDirectory(options.maps), options.map_name, options.route,
        RouteFollowingOptions{.success_radius_m = options.checkpoint_radius_m, .navigator = {}});
    if (viewer) viewer->view().setRoute(route->checkpoints());
  }
  RunCompanions companions{.viewer = viewer.get(),
                           .view_status = {.frames_total = input.frame_count,
                                           .mode = mode,
                                           .sensor = input.sensor_name,
                                           .link = options.link,
                                           .instruction = {}},
                           .semantic_eval = semantic_eval ? &*semantic_eval : nullptr,
                           .pass_log = pass_log ? &*pass_log : nullptr,
                           .route = route ? &*route : nullptr,
                           .edge_map_size = [&edge] { return edge.sessionMapSize(); }};

  Stopwatch wall;
  const PlayedFrames played =
      playFrames(*input.reader,
                 {.frame_count = input.frame_count,
                  .frames_per_pass = input.frames_per_pass,
                  .realtime = options.realtime,
                  .compute_budget = computeBudgetFor(options, mode, input.reader->camera())},
                 slam, companions, wall);
  slam.finish();
  // What the edge's map store holds now (the last changes written first).
  nlohmann::json store_metrics = storeMetrics(edge.store, options.map_name);
  const RunSetup setup{.options = options,
                       .info = info,
                       .sensor_name = input.sensor_name,
                       .sensor = input.sensor,
                       .frame_count = input.frame_count};
  const RunReport report(setup, played, slam, companions, std::move(store_metrics),
                         wall.elapsedMs() / 1000.0);
  report.printSummary();
  report.writeOutputs();
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
  run->add_option("--new-map-after", options->new_map_after_s,
                  "Lost for S seconds (the camera's time) with relocalisation failing, start a new "
                  "map beside the old one; loop closing merges them when the camera sees the old "
                  "places again. Frames tracked in a new map before it is merged are left out of "
                  "the trajectories (trajectory_map<k>.tum has them); 0 = wait for "
                  "relocalisation")
      ->check(CLI::Range(0.0, 3600.0))
      ->capture_default_str();
  auto* max_frames =
      run->add_option("--max-frames", options->max_frames, "Process at most N frames (0 = all)");
  auto* repeat =
      run->add_option("--repeat", options->repeat,
                      "Play the frames N times in a row into one map (the camera jumps back to the "
                      "first frame at each pass); metrics.json \"passes\" has each pass's figures")
          ->check(CLI::Range(1, 1000))
          ->excludes(max_frames)
          ->capture_default_str();
  run->add_flag("--preload", options->preload,
                "Decode the frames to play into memory before the run starts, so that with "
                "--realtime the client's CPU does not pay for reading the files (a device's "
                "camera delivers decoded frames); refused when they would take more than half "
                "of the available memory")
      ->excludes(repeat);
  run->add_option_function<std::string>(
         "--frames",
         [options](const std::string& text) { options->frames = parseFrameRanges(text); },
         "Play only frames A-B of the dataset (0-based, inclusive), as if they were the whole "
         "sequence: one recording standing in for several sessions. Several ranges, "
         "comma-separated (0-200,375-999), are played one after the other: the camera is "
         "elsewhere from one frame to the next")
      ->type_name("A-B[,C-D...]")
      ->check([](const std::string& text) {
        try {
          (void)parseFrameRanges(text);
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
  run->add_option("--compute-adapt", options->compute_adapt,
                  "With --realtime: when frames take longer than the camera's period, the "
                  "client extracts fewer features, then fewer pyramid levels, and returns to "
                  "the configuration once there is room (on|off; metrics.json compute_budget)")
      ->transform(
          CLI::CheckedTransformer(std::map<std::string, bool>{{"on", true}, {"off", false}}));
  run->add_flag("--fast", options->fast, "Feed frames as fast as possible (the default)")
      ->excludes(realtime);
  run->add_flag("--deterministic", options->deterministic,
                "Local mode: map each keyframe (and close loops) before the next frame, on one "
                "thread, so two runs give the same trajectory (for tests and bisecting; slower)")
      ->excludes(realtime);
  run->add_flag("--localize-only", options->localize_only,
                "Localise in the stored map --map and follow it, changing nothing in it (no "
                "keyframe is made). Local mode: the map from --maps, opened read-only. Edge mode "
                "(and client): the edge's stored map; the edge relocalises lost frames against "
                "all of it and sends the part around the camera");
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
