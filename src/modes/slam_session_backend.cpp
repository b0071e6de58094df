#include "modes/slam_session_backend.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "modes/local_slam.h"
#include "store/store_location.h"
#include "store/stored_map_loader.h"
#include "util/timing_stats.h"
#include "wire/slice_splitting.h"
#include "wire/wire_error.h"

namespace edgeslam {
namespace {

// After a restart the edge's ids restart beyond the stored ones by this much: the last second of
// ids before the restart (made, sent to the client, not stored) is never handed out again.
constexpr std::uint64_t kEdgeIdGapAfterRestart = std::uint64_t{1} << 32;

cv::Mat decodeImage(const std::vector<std::uint8_t>& bytes, int flags, const char* what) {
  if (bytes.empty()) return {};
  cv::Mat image = cv::imdecode(bytes, flags);
  if (image.empty()) throw std::invalid_argument(std::string("undecodable ") + what + " image");
  return image;
}

OffloadTrackingState toOffloadState(TrackingState state) {
  switch (state) {
    case TrackingState::kOk:
      return OffloadTrackingState::kOk;
    case TrackingState::kLost:
      return OffloadTrackingState::kLost;
    default:
      return OffloadTrackingState::kNotInitialized;
  }
}

MapSample sampleOf(const Map& map, std::size_t max_points) {
  MapSample sample;
  MutexLock lock(map.updateMutex());
  for (const KeyFrame* kf : map.keyFrames()) {
    if (kf->isBad()) continue;
    sample.keyframe_poses.push_back(kf->poseInverse());
    sample.keyframe_ids.push_back(kf->id());
  }
  sample.points = map.pointPositionSample(max_points);
  sample.total_points = map.pointCount();
  return sample;
}

}  // namespace

SlamSessionBackend::SlamSessionBackend(const SessionConfig& config, SliceSink& sink,
                                       SlamSessionOptions options,
                                       std::shared_ptr<LiveEdgeMaps> live_maps)
    : config_(config),
      store_map_name_(
          !config.map_name.empty() || !options.store
              ? config.map_name
              : defaultMapName(config.client_name + "-s" + std::to_string(config.session_id))),
      sink_(sink),
      options_(options),
      live_maps_(std::move(live_maps)) {
  if (config_.settings.semantic && options_.segmenter) {
    try {
      segmenter_ = makeSegmenter(*options_.segmenter);
    } catch (const std::runtime_error& e) {
      // A missing or broken model is the server's problem, but the session cannot be opened.
      throw std::invalid_argument(std::string("no segmenter for this session: ") + e.what());
    }
  }
  if (config_.settings.localize_only) {
    makeLocalization();
    return;
  }
  // A session naming a map another client writes now joins it. One naming a map the store holds
  // resumes it (a client reconnecting after a restart): loaded now, so that the full resync the
  // client asks for first carries it.
  if (live_maps_ && !config_.map_name.empty()) {
    bool joined = false;
    std::shared_ptr<LiveEdgeMap> live = live_maps_->findOrMake(
        config_.map_name, [&] { return makeMapping(storedSessionToResume()); }, joined);
    if (joined) joinMapping(std::move(live));
    return;
  }
  if (auto resumed = storedSessionToResume()) mapping_ = makeMapping(std::move(resumed));
}

void SlamSessionBackend::joinMapping(std::shared_ptr<LiveEdgeMap> live) {
  if (std::optional<std::string> why = whyCannotJoin(live->made_by, config_)) {
    throw std::invalid_argument(
        fmt::format("map '{}' is being written by another client, and this one cannot join it: {}",
                    config_.map_name, *why));
  }
  MutexLock view_lock(view_mutex_);
  ClientMapWindowOptions window = options_.mapping.window;
  window.keyframes = static_cast<std::size_t>(config_.settings.client_map_keyframes);
  client_ = live->session->addClient(window, [this](MapSlice slice) { publish(std::move(slice)); });
  // Ids of this origin the map holds (a client that had it before): this client's start above.
  id_floor_ = live->session->largestIdOfOrigin(config_.id_origin);
  mapping_ = std::move(live);
  spdlog::info("session {}: joins map '{}', written by {} other client(s) of this server",
               config_.session_id, config_.map_name, mapping_->session->clientCount() - 1);
  if (options_.store && mapping_->store_writer) {
    try {
      joined_store_session_ = options_.store->beginSession(
          config_.map_name, {config_.client_name, config_.camera, config_.sensor});
    } catch (const std::exception& e) {
      spdlog::error("session {}: not recorded in the store: {}", config_.session_id, e.what());
    }
  }
}

SlamSessionBackend::~SlamSessionBackend() {
  if (mapping_) {
    // The map goes on while another client writes it; no slice reaches this session once out.
    mapping_->session->removeClient(client_);
    mapping_.reset();
  }
  if (joined_store_session_) {
    try {
      options_.store->endSession(*joined_store_session_);
    } catch (const std::exception& e) {
      spdlog::error("session {}: its end not recorded in the store: {}", config_.session_id,
                    e.what());
    }
  }
  if (slices_split_.load() + slices_not_sent_.load() > 0) {
    spdlog::info("session {}: {} slices split to fit a message, {} not sent", config_.session_id,
                 slices_split_.load(), slices_not_sent_.load());
  }
}

std::optional<StoredSession> SlamSessionBackend::storedSessionToResume() {
  if (!options_.store || config_.map_name.empty() || config_.sensor == Sensor::kStereo) {
    return std::nullopt;
  }
  std::optional<StoredMap> stored;
  Stopwatch read_timer;
  try {
    stored = options_.store->loadMap(config_.map_name);
  } catch (const std::exception& e) {
    spdlog::error("session {}: map '{}' not loaded: {}", config_.session_id, config_.map_name,
                  e.what());
    return std::nullopt;
  }
  if (!stored) return std::nullopt;
  StoredSession* latest = latestSessionWithKeyFrames(*stored);
  if (latest == nullptr) return std::nullopt;
  if (latest->info.sensor != config_.sensor) {
    spdlog::warn("session {}: map '{}' was made with a {} sensor: not resumed by a {} session",
                 config_.session_id, config_.map_name, toString(latest->info.sensor),
                 toString(config_.sensor));
    return std::nullopt;
  }
  spdlog::info("session {}: map '{}' read from {} in {:.0f} ms", config_.session_id,
               config_.map_name, options_.store->location(), read_timer.elapsedMs());
  return std::move(*latest);
}

void SlamSessionBackend::publish(MapSlice slice) {
  try {
    const SlicePushResult pushed = pushSplitting(sink_, std::move(slice));
    if (pushed.parts > 1) {
      ++slices_split_;
      spdlog::info("session {}: slice sent in {} parts (larger than one message)",
                   config_.session_id, pushed.parts);
    }
  } catch (const std::exception& e) {
    ++slices_not_sent_;
    spdlog::error("session {}: slice not sent ({} so far): {}", config_.session_id,
                  slices_not_sent_.load(), e.what());
  }
}

std::shared_ptr<LiveEdgeMap> SlamSessionBackend::makeMapping(std::optional<StoredSession> resumed) {
  MutexLock view_lock(view_mutex_);
  auto live = std::make_shared<LiveEdgeMap>();
  live->made_by = config_;
  EdgeMapSessionOptions mapping = options_.mapping;
  mapping.backend.mapper.observe_recent_points = true;
  mapping.backend.segmenter = segmenter_;
  // The client bounds its map: the window follows its setting.
  mapping.window.keyframes =
      static_cast<std::size_t>(std::max(0, config_.settings.client_map_keyframes));
  double rebuild_ms = 0.0;
  std::vector<KeyFrameId> stored_keyframes;
  std::vector<KeyFrameId> places_missing;
  std::size_t places_attached = 0;
  if (resumed) {
    mapping.preload = [&](Map& map) {
      Stopwatch timer;
      loadStoredSessionTakingFeatures(*resumed, map);
      // Bags of words stored with the keyframes spare computing them again (~1.8 ms each).
      const std::shared_ptr<const Vocabulary>& vocabulary = mapping.backend.mapper.vocabulary
                                                                ? mapping.backend.mapper.vocabulary
                                                                : mapping.backend.vocabulary;
      if (vocabulary != nullptr && !vocabulary->empty()) {
        AttachedPlaces places =
            attachStoredPlaces(*resumed, map, *vocabulary, vocabulary->checksum(),
                               mapping.backend.mapper.direct_index_depth);
        places_attached = places.attached;
        places_missing = std::move(places.missing);
      }
      // Edge ids made after the last batch the store kept may still name elements a client
      // holds: new ones start well beyond.
      std::uint64_t newest_edge_id = 0;
      for (const KeyFrameRecord& k : resumed->keyframes) {
        stored_keyframes.push_back(k.id);
        if (idOrigin(k.id) == config_.id_origin) id_floor_ = std::max(id_floor_, k.id);
      }
      for (const MapPointRecord& p : resumed->points) {
        if (idOrigin(p.id) == 0) newest_edge_id = std::max(newest_edge_id, p.id);
        if (idOrigin(p.id) == config_.id_origin) id_floor_ = std::max(id_floor_, p.id);
      }
      map.ids().advancePast(newest_edge_id + kEdgeIdGapAfterRestart);
      rebuild_ms = timer.elapsedMs();
    };
  }
  live->session =
      std::make_unique<EdgeMapSession>(config_.camera, config_.sensor, mapping,
                                       [this](MapSlice slice) { publish(std::move(slice)); });
  mapping_ = live;
  client_ = 0;
  if (resumed) {
    const EdgeMapSessionStats loaded = live->session->stats();
    const std::size_t keyframes = std::max<std::size_t>(1, loaded.keyframes_loaded);
    spdlog::info(
        "session {}: map '{}' resumed: {} keyframes, {} points; rebuilt in {:.0f} ms, bags of "
        "words {:.0f} ms ({} stored, {} computed; {:.1f} ms per keyframe)",
        config_.session_id, config_.map_name, loaded.keyframes_loaded, resumed->points.size(),
        rebuild_ms, loaded.load_describe_ms, places_attached, places_missing.size(),
        (rebuild_ms + loaded.load_describe_ms) / static_cast<double>(keyframes));
  }
  startStoreWriter(*live, resumed ? std::optional<StoreSessionId>(resumed->id) : std::nullopt,
                   stored_keyframes, places_missing);
  return live;
}

void SlamSessionBackend::makeLocalization() {
  if (!options_.store) {
    throw std::invalid_argument(
        "localisation needs a stored map, and this edge server keeps none (--maps none)");
  }
  if (config_.map_name.empty()) {
    throw std::invalid_argument("localisation needs the name of a stored map (--map NAME)");
  }
  Stopwatch timer;
  std::optional<StoredMap> stored;
  try {
    stored = options_.store->loadMap(config_.map_name);
  } catch (const std::exception& e) {
    throw std::invalid_argument(
        fmt::format("map '{}' cannot be read: {}", config_.map_name, e.what()));
  }
  if (!stored) {
    throw std::invalid_argument(
        fmt::format("the edge's store {} has no map named '{}' to localise in",
                    options_.store->location(), config_.map_name));
  }
  StoredSession* latest = latestSessionWithKeyFrames(*stored);
  if (latest == nullptr) {
    throw std::invalid_argument(fmt::format("map '{}' has no keyframes", config_.map_name));
  }
  if (latest->info.sensor != config_.sensor) {
    throw std::invalid_argument(
        fmt::format("map '{}' was made with a {} sensor; this client has a {} one",
                    config_.map_name, toString(latest->info.sensor), toString(config_.sensor)));
  }
  const PinholeCamera& made_with = latest->info.camera;
  if (made_with.width() != config_.camera.width() ||
      made_with.height() != config_.camera.height()) {
    throw std::invalid_argument(fmt::format(
        "map '{}' was made with {}x{} images; this client's are {}x{}", config_.map_name,
        made_with.width(), made_with.height(), config_.camera.width(), config_.camera.height()));
  }
  const double read_ms = timer.elapsedMs();
  EdgeLocalizationSessionOptions options;
  options.vocabulary = options_.mapping.backend.mapper.vocabulary
                           ? options_.mapping.backend.mapper.vocabulary
                           : options_.mapping.backend.vocabulary;
  if (config_.settings.client_map_keyframes > 0) {
    options.window_keyframes = static_cast<std::size_t>(config_.settings.client_map_keyframes);
  }
  MutexLock view_lock(view_mutex_);
  localization_ = std::make_unique<EdgeLocalizationSession>(
      config_.camera, options, [&](Map& map) { loadStoredSessionTakingFeatures(*latest, map); },
      [this](MapSlice slice) { publish(std::move(slice)); });
  spdlog::info(
      "session {}: localising in map '{}' ({} keyframes, {} points), read-only: read in {:.0f} "
      "ms, ready in {:.0f} ms",
      config_.session_id, config_.map_name, localization_->keyFrameCount(), latest->points.size(),
      read_ms, timer.elapsedMs());
}

void SlamSessionBackend::onKeyFrame(KeyFrameUpload upload) {
  if (localization_) {
    localization_->onQuery(upload);
    return;
  }
  if (upload.localization_query) {
    throw std::invalid_argument("a localisation query in a session that maps (not localize-only)");
  }
  if (!mapping_) makeMapping(std::nullopt);
  mapping().onKeyFrame(upload, client_);
}

void SlamSessionBackend::onFullResyncRequested() {
  if (localization_) {
    localization_->publishFullResync();
    return;
  }
  // A session with nothing mapped yet (no stored map to resume) answers with an empty map: the
  // client then sends again every keyframe it holds.
  if (!mapping_) makeMapping(std::nullopt);
  mapping().publishFullResync(client_);
}

void SlamSessionBackend::startStoreWriter(LiveEdgeMap& live, std::optional<StoreSessionId> resumed,
                                          const std::vector<KeyFrameId>& stored_keyframes,
                                          const std::vector<KeyFrameId>& places_missing) {
  if (!options_.store) return;
  const std::string& map = store_map_name_;
  try {
    StoreSessionId session = 0;
    if (resumed) {
      session = *resumed;
      options_.store->resumeSession(session);
    } else {
      session =
          options_.store->beginSession(map, {config_.client_name, config_.camera, config_.sensor});
    }
    live.store_writer = std::make_unique<MapStoreWriter>(options_.store, session,
                                                         live.session->map(), options_.store_stats);
    live.store_writer->assumeStored(stored_keyframes);
    live.store_writer->storePlacesOf(places_missing);
    live.session->setChangeObserver(live.store_writer.get());
    spdlog::info("session {}: writing map '{}' to {}{}", config_.session_id, map,
                 options_.store->location(), resumed ? " (resumed)" : "");
  } catch (const std::exception& e) {
    // The session still maps; only its persistence is lost, and said so.
    spdlog::error("session {}: map '{}' not stored: {}", config_.session_id, map, e.what());
  }
}

std::optional<OffloadResult> SlamSessionBackend::onFrame(OffloadFrame frame) {
  Stopwatch timer;
  const cv::Mat gray = decodeImage(frame.image_bytes, cv::IMREAD_GRAYSCALE, "colour");
  if (gray.empty()) throw std::invalid_argument("offloaded frame without an image");
  cv::Mat depth;
  if (config_.sensor != Sensor::kMonocular && !frame.depth_bytes.empty()) {
    const cv::Mat raw = decodeImage(frame.depth_bytes, cv::IMREAD_UNCHANGED, "depth");
    if (raw.type() != CV_16U) throw std::invalid_argument("offloaded depth must be 16-bit mm");
    raw.convertTo(depth, CV_32F, 1.0 / 1000.0);
  }
  if (!offload_) {
    MutexLock view_lock(view_mutex_);
    SlamOptions slam_options = defaultSlamOptions(config_.camera, config_.sensor);
    slam_options.orb.num_features = config_.settings.features;
    slam_options.orb.num_levels = config_.settings.pyramid_levels;
    slam_options.orb.scale_factor = config_.settings.scale_factor;
    slam_options.semantic = segmenter_ != nullptr;
    slam_options.backend.segmenter = segmenter_;
    // Each frame's pose goes back as it is tracked; nothing would carry an end-of-session
    // refinement to the client.
    slam_options.refine_intrinsics = false;
    // Recorded frames fed back to back: the same offline pacing as local mode's.
    slam_options.wait_for_backend = config_.settings.frames_back_to_back;
    offload_ = std::make_unique<LocalSlam>(config_.camera, slam_options);
  }
  const double waited_before_ms = offload_->backendWaitTotalMs();
  const TrackResult tracked = offload_->process(frame.frame_index, frame.timestamp, gray, depth);
  OffloadResult result;
  result.backend_wait_ms = offload_->backendWaitTotalMs() - waited_before_ms;
  result.frame_index = frame.frame_index;
  result.state = toOffloadState(tracked.state);
  result.T_cw = tracked.T_cw;
  result.server_ms = timer.elapsedMs();
  return result;
}

std::optional<std::string> SlamSessionBackend::failure() const {
  MutexLock view_lock(view_mutex_);
  if (offload_) return offload_->failure();
  if (mapping_) return mapping().failure();
  return std::nullopt;
}

BackendCosts SlamSessionBackend::costs() const {
  MutexLock view_lock(view_mutex_);
  BackendCosts costs;
  if (localization_) {
    const EdgeLocalizationStats stats = localization_->stats();
    costs.stages_ms.emplace_back("relocalization", stats.relocalization_ms.summary());
    return costs;
  }
  if (!mapping_) return costs;
  const EdgeMapSessionStats session = mapping().stats();
  costs.map_keyframes = session.keyframes;
  costs.map_points = session.map_points;
  const LocalMapperStats mapper = mapping().mapper().stats();
  costs.stages_ms.emplace_back("keyframe_mapping", mapper.keyframe_ms.summary());
  costs.stages_ms.emplace_back("local_ba", mapper.local_ba_ms.summary());
  if (const LoopCloser* closer = mapping().loopCloser()) {
    const LoopCloserStats loops = closer->stats();
    costs.stages_ms.emplace_back("loop_detection", loops.detection_ms.summary());
    SampleStats correction;
    for (const LoopEvent& event : loops.events) correction.add(event.correction_ms);
    costs.stages_ms.emplace_back("loop_correction", correction.summary());
    SampleStats global_ba;
    for (const double ms : loops.global_ba_ms) global_ba.add(ms);
    costs.stages_ms.emplace_back("global_ba", global_ba.summary());
    costs.stages_ms.emplace_back("global_ba_handover", loops.global_ba_handover_ms.summary());
  }
  return costs;
}

MapSample SlamSessionBackend::mapSample(std::size_t max_points) const {
  MutexLock view_lock(view_mutex_);
  if (offload_) return offload_->mapSample(max_points);
  if (localization_) return sampleOf(localization_->map(), max_points);
  if (mapping_) return sampleOf(mapping().map(), max_points);
  return {};
}

std::size_t SlamSessionBackend::loops() const {
  MutexLock view_lock(view_mutex_);
  if (mapping_ && mapping().loopCloser() != nullptr) return mapping().loopCloser()->loops();
  return 0;
}

std::vector<LoopEvent> SlamSessionBackend::loopEvents() const {
  MutexLock view_lock(view_mutex_);
  if (mapping_ && mapping().loopCloser() != nullptr) return mapping().loopCloser()->stats().events;
  return {};
}

SlamSessionBackend::MapIdentity SlamSessionBackend::mapIdentity() const {
  MutexLock view_lock(view_mutex_);
  MapIdentity identity{.name = store_map_name_};
  if (offload_) {
    identity.name = config_.map_name;  // offloaded SLAM keeps its map in memory only
    identity.map = offload_.get();
  }
  if (localization_) {
    identity.map = localization_.get();
    identity.localize_only = true;
  }
  if (mapping_) identity.map = mapping_.get();
  return identity;
}

std::unique_ptr<EdgeSessionBackend> SlamSessionFactory::open(const SessionConfig& config,
                                                             SliceSink& sink) {
  if (config.sensor == Sensor::kStereo) {
    throw std::invalid_argument("stereo sessions are not supported yet");
  }
  if (config.settings.semantic && !options_.segmenter) {
    throw std::invalid_argument(
        "the client asks for semantic culling and this edge server has no segmenter (start it "
        "with --semantic on and the models)");
  }
  if (!config.map_name.empty()) checkMapName(config.map_name);
  spdlog::info("edge: session {} for '{}' ({}x{}, {})", config.session_id, config.client_name,
               config.camera.width(), config.camera.height(), toString(config.sensor));
  return std::make_unique<SlamSessionBackend>(config, sink, options_, live_maps_);
}

}  // namespace edgeslam
