#include "server/edge_map_session.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "map/map_replication.h"
#include "semantic/label_encoding.h"
#include "server/omitted_descriptors.h"
#include "server/slice_builder.h"
#include "util/timing_stats.h"

namespace edgeslam {

MappingBackendOptions edgeSessionBackendOptions() {
  MappingBackendOptions options;
  options.thread_nice_when_segmenting = 10;
  return options;
}

EdgeMapSession::EdgeMapSession(const PinholeCamera& camera, Sensor sensor,
                               EdgeMapSessionOptions options, Publish publish)
    : camera_(camera), mask_downscale_(std::max(1, options.mask_downscale)) {
  {
    MutexLock lock(map_.updateMutex());
    first_client_ =
        clients_.emplace(0, std::make_unique<Client>(options.window, std::move(publish)))
            .first->second.get();
  }
  MappingBackendHooks hooks;
  hooks.keyframe_mapped = [this](KeyFrame* keyframe) { publishSlice(keyframe); };
  hooks.map_corrected = [this] { publishSlice(nullptr); };
  hooks.keyframe_segmented = [this](KeyFrameSegmentationResult result) {
    onSegmented(std::move(result));
  };
  // The loop closer tells of a merge under the map's update mutex.
  hooks.parts_merged = [this](const MapPartMerge& merge)
                           NO_THREAD_SAFETY_ANALYSIS { onPartsMerged(merge); };
  backend_ = std::make_unique<MappingBackend>(map_, camera_, sensor, std::move(options.backend),
                                              std::move(hooks));
  if (options.preload) options.preload(map_);
  adoptPreloadedMap();
  backend_->start();
}

void EdgeMapSession::adoptPreloadedMap() {
  std::vector<KeyFrame*> loaded;
  KeyFrameId newest = kInvalidId;
  {
    MutexLock lock(map_.updateMutex());
    Client& first = clientLocked(0);
    for (KeyFrame* keyframe : map_.keyFrames()) {
      if (keyframe->isBad()) continue;
      loaded.push_back(keyframe);
      first.window.clientHolds(keyframe->id());
      newest = std::max(newest, keyframe->id());
    }
    if (!loaded.empty()) first.newest_keyframe = newest;
  }
  if (loaded.empty()) return;
  // Before the threads start: nothing else touches the keyframes' places or the loop database.
  Stopwatch timer;
  backend_->adoptLoadedKeyFrames(loaded);
  MutexLock state(state_mutex_);
  stats_.keyframes_loaded = loaded.size();
  stats_.load_describe_ms = timer.elapsedMs();
  stats_.keyframes = loaded.size();
}

EdgeMapSession::~EdgeMapSession() {
  stop();
  const EdgeMapSessionStats totals = stats();
  if (totals.descriptors_filled + totals.descriptors_lost > 0) {
    spdlog::info(
        "edge session: {} uploaded keypoints took their map point's descriptor, {} lost theirs "
        "(point gone)",
        totals.descriptors_filled, totals.descriptors_lost);
  }
}

void EdgeMapSession::stop() {
  backend_->stop();
}

EdgeMapSession::Client& EdgeMapSession::clientLocked(EdgeMapClientId client) const {
  const auto it = clients_.find(client);
  if (it == clients_.end()) {
    throw std::invalid_argument("client " + std::to_string(client) + " is not in the session");
  }
  return *it->second;
}

EdgeMapClientId EdgeMapSession::addClient(ClientMapWindowOptions window, Publish publish) {
  if (window.keyframes == 0) {
    throw std::invalid_argument(
        "a client joining a map other clients write needs a bounded map (client map keyframes "
        "> 0): it learns of their keyframes as they enter its window");
  }
  MutexLock publishing(publish_mutex_);
  MutexLock lock(map_.updateMutex());
  const EdgeMapClientId id = next_client_++;
  clients_.emplace(id, std::make_unique<Client>(window, std::move(publish)));
  return id;
}

void EdgeMapSession::removeClient(EdgeMapClientId client) {
  MutexLock publishing(publish_mutex_);
  MutexLock lock(map_.updateMutex());
  if (client == 0) first_client_ = nullptr;
  clients_.erase(client);
}

std::size_t EdgeMapSession::clientCount() const {
  MutexLock lock(map_.updateMutex());
  return clients_.size();
}

std::uint64_t EdgeMapSession::largestIdOfOrigin(std::uint8_t origin) const {
  MutexLock lock(map_.updateMutex());
  std::uint64_t largest = 0;
  for (const KeyFrame* keyframe : map_.keyFrames()) {
    if (idOrigin(keyframe->id()) == origin) largest = std::max(largest, keyframe->id());
  }
  for (const MapPoint* point : map_.mapPoints()) {
    if (idOrigin(point->id()) == origin) largest = std::max(largest, point->id());
  }
  return largest;
}

void EdgeMapSession::onKeyFrame(const KeyFrameUpload& upload, EdgeMapClientId client_id) {
  cv::Mat image;
  if (backend_->segments() && !upload.image_bytes.empty()) {
    image = cv::imdecode(upload.image_bytes, cv::IMREAD_UNCHANGED);
    if (image.empty() || (image.type() != CV_8UC1 && image.type() != CV_8UC3)) {
      throw std::invalid_argument("keyframe image (" + upload.image_encoding + ", " +
                                  std::to_string(upload.image_bytes.size()) +
                                  " bytes) is not an 8-bit grey or colour image");
    }
  }
  KeyFrame* keyframe = nullptr;
  {
    MutexLock lock(map_.updateMutex());
    Client& client = clientLocked(client_id);
    if (!upload.map_reset && map_.keyFrame(upload.keyframe.id) != nullptr) {
      // Re-sent after a full resync while its first upload was still on its way, or sent to a
      // server that stored it before a restart: the map has it. The client waits for an answer.
      lock.unlock();
      {
        MutexLock state(state_mutex_);
        ++stats_.uploads_duplicate;
      }
      publishSlice(nullptr, upload.sequence, client_id);
      return;
    }
    if (upload.map_reset) {
      if (clients_.size() == 1) {
        backend_->onMapReset();
        map_.clear();
        if (observer_ != nullptr) observer_->onMapCleared();
      } else {
        // The others' keyframes stay; the client's old ones stay in the map, in their own part.
        spdlog::warn(
            "edge map: a client started its map again; the map others write keeps what "
            "it had made");
      }
      client.window.clear();
      client.window_centre = kInvalidId;
    }
    // Descriptors the wire left out are those of points this map has (or had).
    const KeyFrameRecord* record = &upload.keyframe;
    KeyFrameRecord filled;
    OmittedDescriptorFill fill;
    if (!upload.keyframe.features.descriptor_omitted.empty()) {
      filled = upload.keyframe;
      fill = fillOmittedDescriptors(map_, filled);
      record = &filled;
      if (!fill.lost.empty()) {
        spdlog::debug(
            "keyframe {:#x}: {} keypoints name points this map no longer has and came without "
            "descriptors: they keep neither (first: keypoint {})",
            filled.id, fill.lost.size(), fill.lost.front());
      }
    }
    std::vector<MapPointRecord> new_points = upload.new_points;
    KeyFrameRecord moved;
    if (const std::optional<Sim3d> world = partMoveMissedBy(*record)) {
      moved = *record;
      moved.T_cw = (Sim3d(moved.T_cw) * world->inverse()).toSE3();
      for (MapPointRecord& point : new_points) point.position = *world * point.position;
      record = &moved;
      spdlog::info(
          "edge map: keyframe {:#x} was tracked before its client heard of a merge: "
          "moved with its part",
          moved.id);
    }
    // The client already has what it sent: apply it without recording it for the slices.
    map_.setChangeRecording(false);
    std::vector<UploadedPointConflict> conflicts;
    try {
      rebuildPositionsFromDepth(new_points, *record, camera_);
      keyframe = insertKeyFrameRecord(map_, *record, camera_);
      for (const MapPointRecord& point : new_points) {
        if (map_.mapPoint(point.id) != nullptr) continue;
        // Normal, descriptor and distance range follow from the observations: the upload need
        // not carry them.
        if (auto conflict = insertUploadedPoint(map_, point, upload.keyframe.id)) {
          conflicts.push_back(*conflict);
        }
      }
    } catch (...) {
      map_.setChangeRecording(true);
      throw;
    }
    map_.setChangeRecording(true);
    if (record == &moved) {
      // The client has them where it tracked them, in its part's frame before the merge: the
      // next slice carries the move.
      map_.setKeyFramePose(keyframe, keyframe->pose());
      for (const MapPointRecord& point : new_points) {
        if (MapPoint* p = map_.mapPoint(point.id); p != nullptr && !p->isBad()) {
          map_.setPointPosition(p, p->position());
        }
      }
    }
    // Where the edge's map differs from what the client sent, the slices say so.
    resolveUploadedPointConflicts(map_, conflicts);
    if (observer_ != nullptr) {
      // Applied without recording (the client has it): the observer still needs all of it.
      MapChanges uploaded;
      uploaded.keyFrameCreated(keyframe->id());
      for (const MapPoint* point : keyframe->points()) {
        if (point != nullptr) uploaded.pointUpdated(point->id());
      }
      observer_->onMapChanged(uploaded);
    }
    client.window.clientHolds(keyframe->id());
    client.upload_of_keyframe[keyframe->id()] = upload.sequence;
    client.newest_keyframe = keyframe->id();
    MutexLock state(state_mutex_);
    ++stats_.uploads;
    stats_.descriptors_filled += fill.filled;
    stats_.descriptors_lost += fill.lost.size();
  }
  if (upload.segmenter_nms > 0.f) backend_->setNmsThreshold(upload.segmenter_nms);
  if (!image.empty()) {
    backend_->segment({keyframe->id(), keyframe->frameIndex(), std::move(image),
                       cv::Size(camera_.width(), camera_.height())});
  }
  backend_->insertKeyFrame(keyframe);
  backend_->processAll();
}

void EdgeMapSession::publishSlice(KeyFrame* mapped, std::uint64_t answers,
                                  EdgeMapClientId answered) {
  MutexLock publishing(publish_mutex_);
  std::vector<std::pair<const Publish*, MapSlice>> outgoing;
  {
    MutexLock lock(map_.updateMutex());
    const std::size_t loops = backend_->loops();
    std::vector<MaskRecord> masks;
    {
      MutexLock state(state_mutex_);
      masks.swap(pending_masks_);
    }
    const bool loops_unpublished =
        std::any_of(clients_.begin(), clients_.end(),
                    [&](const auto& c) { return c.second->loops_published != loops; });
    if (mapped == nullptr && answers == 0 && map_.changes().empty() && !loops_unpublished &&
        masks.empty()) {
      return;
    }
    MapChanges changes = map_.takeChanges();
    if (observer_ != nullptr) {
      observer_->onMapChanged(changes);
      if (!masks.empty()) observer_->onMasks(masks);
    }
    MapSlice common = buildSlice(map_, changes);
    std::size_t left = clients_.size();
    for (auto& [id, client] : clients_) {
      // Each client's slice is cut from the common one; the last takes it.
      MapSlice base = --left == 0 ? std::move(common) : common;
      // A client alone had every keyframe mapped for it (one loaded, or uploaded before a reset).
      const bool mapped_for_client =
          mapped != nullptr &&
          (clients_.size() == 1 || client->upload_of_keyframe.contains(mapped->id()));
      const bool answers_client = mapped_for_client || (answers != 0 && id == answered);
      std::optional<MapSlice> slice =
          sliceFor(*client, std::move(base), mapped_for_client ? mapped : nullptr, answers_client,
                   answers_client ? answers : 0, loops, masks);
      if (slice) outgoing.emplace_back(&client->publish, std::move(*slice));
    }
  }
  for (auto& [publish, slice] : outgoing) {
    if (*publish) (*publish)(std::move(slice));
  }
}

std::optional<MapSlice> EdgeMapSession::sliceFor(Client& client, MapSlice slice, KeyFrame* mapped,
                                                 bool answers_client, std::uint64_t answers,
                                                 std::size_t loops,
                                                 const std::vector<MaskRecord>& masks) {
  // A keyframe culled as soon as it was mapped (a revisit) hands the window to the keyframe it
  // hangs from in the spanning tree, near where the camera is.
  KeyFrame* centre = mapped;
  while (centre != nullptr && centre->isBad()) centre = centre->parent();
  if (centre != nullptr) client.window_centre = centre->id();
  // Loop corrections, global BA and the other clients' keyframes keep the window of the client's
  // last mapped keyframe.
  const std::size_t entering_before = slice.keyframes.size();
  client.window.shape(map_, map_.keyFrame(client.window_centre), slice);
  // Masks of the keyframes the client holds (a client alone gets all of them, as it always did).
  if (clients_.size() == 1) {
    slice.masks = masks;
  } else {
    for (const MaskRecord& mask : masks) {
      if (client.window.holds(mask.keyframe)) slice.masks.push_back(mask);
    }
  }
  if (clients_.size() > 1 && !answers_client && loops == client.loops_published &&
      slice.keyframes.empty() && slice.keyframes_evicted.empty() &&
      slice.keyframes_erased.empty() && slice.points_upserted.empty() &&
      slice.point_positions.empty() && slice.points_erased.empty() && slice.masks.empty() &&
      std::none_of(slice.keyframe_poses.begin(), slice.keyframe_poses.end(),
                   [&](const KeyFramePoseRecord& pose) { return client.window.holds(pose.id); })) {
    return std::nullopt;  // another client's keyframe far from this one
  }
  slice.map_keyframes = map_.keyFrameCount();
  slice.map_points = map_.pointCount();
  if (mapped != nullptr) {
    slice.processed_keyframe = mapped->id();
    if (!mapped->isBad()) {
      slice.reference_keyframe = mapped->id();
      slice.reference_pose = mapped->pose();
    }
  }
  tellLoops(client, loops, slice);
  slice.sequence = ++client.slice_sequence;
  // A correction answers no upload. The slice answers the upload of the keyframe it mapped (later
  // uploads may be queued).
  slice.upload_sequence = answers;
  if (mapped != nullptr) {
    const auto it = client.upload_of_keyframe.find(mapped->id());
    if (it != client.upload_of_keyframe.end()) {
      slice.upload_sequence = it->second;
      client.upload_of_keyframe.erase(it);
    }
  }
  slice.newest_keyframe = client.newest_keyframe;
  MutexLock state(state_mutex_);
  ++stats_.slices;
  if (client.window.bounded()) {
    if (mapped != nullptr || clients_.size() == 1) {
      stats_.client_keyframes_held = client.window.held().size();
    }
    stats_.client_keyframes_evicted += slice.keyframes_evicted.size();
    stats_.client_keyframes_resent += slice.keyframes.size() - entering_before;
  }
  stats_.keyframes = map_.keyFrameCount();
  stats_.map_points = map_.pointCount();
  return slice;
}

void EdgeMapSession::publishFullResync(EdgeMapClientId client_id) {
  MutexLock publishing(publish_mutex_);
  MapSlice slice;
  const Publish* publish = nullptr;
  std::vector<std::pair<const Publish*, MapSlice>> to_others;
  {
    MutexLock lock(map_.updateMutex());
    Client& client = clientLocked(client_id);
    publish = &client.publish;
    // What changed since the last slice is in the whole map sent now; the store still needs it,
    // and the other clients get it in their next slice.
    MapChanges changes = map_.takeChanges();
    if (observer_ != nullptr) observer_->onMapChanged(changes);
    if (clients_.size() > 1) {
      const MapSlice common = buildSlice(map_, changes);
      for (auto& [id, other] : clients_) {
        if (id == client_id) continue;
        if (std::optional<MapSlice> theirs =
                sliceFor(*other, MapSlice(common), nullptr, false, 0, backend_->loops(), {})) {
          to_others.emplace_back(&other->publish, std::move(*theirs));
        }
      }
    }
    slice.full_resync = true;
    for (const KeyFrame* keyframe : map_.keyFrames()) {
      if (keyframe->isBad()) continue;
      slice.keyframe_poses.push_back(keyFramePoseRecord(*keyframe));
    }
    for (const MapPoint* point : map_.mapPoints()) {
      if (!point->isBad()) slice.points_upserted.push_back(mapPointRecord(*point));
    }
    // Points are attached only to keyframes the client holds; a bounded client ignores the rest.
    slice.map_keyframes = map_.keyFrameCount();
    slice.map_points = map_.pointCount();
    const std::size_t loops = backend_->loops();
    tellLoops(client, loops, slice);
    slice.sequence = ++client.slice_sequence;
    // newest_keyframe stays unset: the client must not drop observations in its own keyframes
    // that the edge lacks (it re-sends those keyframes).
    MutexLock state(state_mutex_);
    ++stats_.slices;
    ++stats_.full_resyncs;
  }
  if (*publish) (*publish)(std::move(slice));
  for (auto& [other, theirs] : to_others) {
    if (*other) (*other)(std::move(theirs));
  }
}

void EdgeMapSession::onSegmented(KeyFrameSegmentationResult result) {
  // The back end has erased the keyframe's movable points; the mask goes to the client with them.
  MaskRecord mask;
  mask.keyframe = result.keyframe;
  mask.bytes = encodeLabelImage(result.labels, mask_downscale_, mask.encoding);
  mask.width = (result.labels.cols + mask_downscale_ - 1) / mask_downscale_;
  mask.height = (result.labels.rows + mask_downscale_ - 1) / mask_downscale_;
  mask.segmentation_ms = result.segmentation_ms;
  {
    MutexLock state(state_mutex_);
    pending_masks_.push_back(std::move(mask));
  }
  publishSlice(nullptr);
}

void EdgeMapSession::tellLoops(Client& client, std::size_t loops, MapSlice& slice) {
  slice.loops_closed = static_cast<std::uint32_t>(loops - client.loops_published);
  slice.maps_merged = static_cast<std::uint32_t>(client.merges_moved - client.merges_published);
  client.merges_published = client.merges_moved;
  if (const LoopCloser* closer = backend_->loopCloser();
      closer != nullptr && loops > client.loops_published && client.window_centre != kInvalidId) {
    const std::uint8_t origin = idOrigin(client.window_centre);
    std::vector<LoopEvent> events = closer->eventsFrom(client.loops_published);
    events.resize(std::min(events.size(), loops - client.loops_published));
    for (const LoopEvent& event : events) {
      if (idOrigin(event.current) != origin || idOrigin(event.loop) != origin) continue;
      slice.loops.push_back({event.current_frame, event.loop_frame});
    }
  }
  client.loops_published = loops;
}

void EdgeMapSession::onPartsMerged(const MapPartMerge& merge) {
  for (auto& [id, client] : clients_) {
    if (std::find(merge.moved.begin(), merge.moved.end(), client->window_centre) !=
        merge.moved.end()) {
      ++client->merges_moved;
    }
  }
  MutexLock lock(moves_mutex_);
  part_moves_.push_back({merge.world, {merge.moved.begin(), merge.moved.end()}});
}

std::optional<Sim3d> EdgeMapSession::partMoveMissedBy(const KeyFrameRecord& record) {
  const KeyFrame* parent = map_.keyFrame(record.parent);
  if (parent == nullptr) return std::nullopt;
  MutexLock lock(moves_mutex_);
  std::optional<Sim3d> world;
  SE3d pose = record.T_cw;
  for (PartMove& move : part_moves_) {
    if (!move.moved.contains(parent->id())) continue;
    // Tracked before its client applied the move, it lies as far from its parent's new place as
    // the move was; tracked after, it is near it already.
    const SE3d candidate = (Sim3d(pose) * move.world.inverse()).toSE3();
    const Eigen::Vector3d there = parent->cameraCenter();
    if ((candidate.inverse().translation() - there).norm() >=
        (pose.inverse().translation() - there).norm()) {
      continue;
    }
    pose = candidate;
    world = world ? move.world * *world : move.world;
    // Its client's next keyframes, tracked against it before the client heard, follow it too.
    move.moved.insert(record.id);
  }
  return world;
}

void EdgeMapSession::setNmsThreshold(float nm) {
  backend_->setNmsThreshold(nm);
}

void EdgeMapSession::finish() {
  backend_->waitUntilIdle();
}

std::optional<std::string> EdgeMapSession::failure() const {
  return backend_->failure();
}

EdgeMapSessionStats EdgeMapSession::stats() const {
  const MappingBackendCounters backend = backend_->counters();
  MutexLock state(state_mutex_);
  EdgeMapSessionStats out = stats_;
  out.keyframes_segmented = backend.keyframes_segmented;
  out.movable_points_erased = backend.movable_points_erased;
  return out;
}

}  // namespace edgeslam
