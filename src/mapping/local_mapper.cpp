#include "mapping/local_mapper.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <unordered_set>

#include "map/map_matching.h"
#include "map/pair_triangulation.h"
#include "util/failpoint.h"

namespace edgeslam {

std::string_view toString(TriangulationSearch search) {
  return search == TriangulationSearch::kBagOfWords ? "bow" : "band";
}

std::optional<TriangulationSearch> parseTriangulationSearch(std::string_view text) {
  if (text == "bow") return TriangulationSearch::kBagOfWords;
  if (text == "band") return TriangulationSearch::kEpipolarBand;
  return std::nullopt;
}

LocalMapper::LocalMapper(Map& map, const PinholeCamera& camera, LocalMapperOptions options)
    : map_(map),
      camera_(camera),
      options_(std::move(options)),
      map_participant_(map, "local mapping"),
      queue_("local mapping", [this](KeyFrame* keyframe) { mapNext(keyframe); },
             {.capacity = 0,
              .thread_nice = options_.thread_nice,
              .on_failure = {},
              .group = [](KeyFrame* const& keyframe) -> std::uint64_t {
                return idOrigin(keyframe->id());
              },
              .backlog = options_.max_queue}) {}

LocalMapper::~LocalMapper() {
  stop();
  const LocalMapperStats s = stats();
  if (s.triangulation_searches > 0) {
    spdlog::info(
        "local mapping: {} triangulation searches ({} by bag of words), {} pairs, {:.2f} ms per "
        "search, {} points created",
        s.triangulation_searches, s.triangulation_bow_searches, s.triangulation_pairs,
        s.triangulation_search_ms / static_cast<double>(s.triangulation_searches),
        s.points_created);
  }
}

void LocalMapper::start() {
  queue_.start();
}

void LocalMapper::stop() {
  queue_.stop();
}

void LocalMapper::insertKeyFrame(KeyFrame* keyframe) {
  queue_.push(keyframe);  // a running local BA gives way to it
}

bool LocalMapper::acceptsKeyFrames() const {
  return !queue_.failed() && queue_.size() < options_.max_queue;
}

void LocalMapper::onMapReset() {
  queue_.clear();
  // recent_points_ belongs to the mapping thread: it drops them before its next keyframe.
  reset_requested_ = true;
}

bool LocalMapper::hasPending(KeyFrame* keyframe) const {
  // The keyframe's own client's: it is the one that tracks on from them. Another client's
  // waiting keyframe cut this one's mapping short whenever the two interleaved: two monocular
  // clients mapping redkitchen at once tracked ~50 points where one alone tracked ~150. Unless
  // the clients together made a backlog: then mapping in short keeps up with them.
  return queue_.hasQueuedOfGroup(keyframe) || queue_.size() >= options_.max_queue;
}

LocalMapperStats LocalMapper::stats() const {
  MutexLock lock(stats_mutex_);
  return stats_;
}

void LocalMapper::pause() {
  queue_.pause();
}

void LocalMapper::resume() {
  queue_.resume();
}

void LocalMapper::waitUntilIdle() {
  if (!queue_.running()) {
    processAll();
    return;
  }
  queue_.waitUntilIdle();
}

void LocalMapper::processAll() {
  queue_.processAll();
}

void LocalMapper::mapNext(KeyFrame* keyframe) {
  processKeyFrame(keyframe);
  releaseErased();
}

void LocalMapper::releaseErased() {
  MutexLock lock(map_.updateMutex());
  recent_points_.remove_if([](const MapPoint* p) { return p->isBad(); });
  map_participant_.quiescent(map_);
}

void LocalMapper::processKeyFrame(KeyFrame* keyframe) {
  failpoint("local_mapping");
  const Stopwatch timer;
  mapKeyFrame(keyframe);
  {
    MutexLock lock(stats_mutex_);
    ++stats_.keyframes_processed;
    stats_.keyframe_ms.add(timer.elapsedMs());
  }
  if (on_mapped_) on_mapped_(keyframe);
}

bool LocalMapper::searchesByBow() const {
  return options_.triangulation_search == TriangulationSearch::kBagOfWords &&
         options_.vocabulary != nullptr && !options_.vocabulary->empty();
}

void LocalMapper::describe(KeyFrame* keyframe) const {
  if (!searchesByBow()) return;
  if (const auto place = keyframe->place();
      place != nullptr && place->direct_index_depth == options_.direct_index_depth &&
      place->vocabulary == options_.vocabulary.get()) {
    return;
  }
  // The features never change: no lock needed.
  auto place = std::make_shared<KeyFramePlace>();
  place->direct_index_depth = options_.direct_index_depth;
  place->vocabulary = options_.vocabulary.get();
  const int levels_up = std::max(0, options_.vocabulary->levels() - options_.direct_index_depth);
  options_.vocabulary->transform(keyframe->features().descriptors, levels_up, place->bow,
                                 place->features);
  keyframe->setPlace(std::move(place));
}

void LocalMapper::mapKeyFrame(KeyFrame* keyframe) {
  if (reset_requested_.exchange(false)) recent_points_.clear();
  {
    // Once erased, a keyframe's features may be freed at any quiescent point.
    MutexLock lock(map_.updateMutex());
    if (keyframe->isBad()) return;
  }
  describe(keyframe);
  {
    MutexLock lock(map_.updateMutex());
    if (keyframe->isBad()) return;
    linkKeyFrame(keyframe);
    if (options_.observe_recent_points) observeRecentPoints(keyframe);
    cullRecentPoints(keyframe);
  }
  createNewPoints(keyframe);
  if (!hasPending(keyframe)) fuseWithNeighbours(keyframe);
  if (!hasPending(keyframe)) {
    bool enough_keyframes = false;
    {
      MutexLock lock(map_.updateMutex());
      enough_keyframes = map_.keyFrameCount() > 2 && !keyframe->isBad();
    }
    if (enough_keyframes && options_.run_local_ba) {
      const Stopwatch ba_timer;
      localBundleAdjustment(map_, keyframe, camera_, queue_.giveWay());
      MutexLock lock(stats_mutex_);
      ++stats_.local_ba_runs;
      stats_.local_ba_ms.add(ba_timer.elapsedMs());
    }
    if (options_.cull_keyframes) cullKeyFrames(keyframe);
  }
  if (options_.cull_keyframes && options_.cull_revisits) cullRevisit(keyframe);
  last_optimized_frame_ = keyframe->frameIndex();
}

void LocalMapper::linkKeyFrame(KeyFrame* keyframe) {
  // Tracking linked the observations; points the keyframe created itself (RGB-D) are recent.
  for (MapPoint* p : keyframe->goodPoints()) {
    if (p->firstKeyFrameId() == keyframe->id()) recent_points_.push_back(p);
    map_.refreshPoint(p);
  }
  map_.updateConnections(keyframe);
}

void LocalMapper::observeRecentPoints(KeyFrame* keyframe) {
  // Only the keyframe's own client's: another client's recent points may be in another part of
  // the map, in another frame, where a projection matches by chance.
  // And only those seen from the keyframe's covisibility neighbourhood (two links deep): a keyframe
  // that starts a new map after its client was lost for good is placed where the old map's last
  // recent points still project, and observing them would join the two maps by chance, before a
  // loop can merge them as a whole.
  std::unordered_set<KeyFrameId> near{keyframe->id()};
  for (const auto& [kf, weight] : keyframe->connections()) {
    near.insert(kf->id());
    for (const auto& [kf2, weight2] : kf->connections()) near.insert(kf2->id());
  }
  const auto seenNear = [&](const MapPoint* p) {
    return std::any_of(p->observations().begin(), p->observations().end(),
                       [&](const auto& observation) { return near.contains(observation.first); });
  };
  std::vector<MapPoint*> candidates;
  for (MapPoint* p : recent_points_) {
    if (!p->isBad() && idOrigin(p->firstKeyFrameId()) == idOrigin(keyframe->id()) &&
        !p->observations().contains(keyframe->id()) && seenNear(p)) {
      candidates.push_back(p);
    }
  }
  if (candidates.empty()) return;
  const int observed = fuse(map_, keyframe, candidates, camera_);
  if (observed > 0) map_.updateConnections(keyframe);
  spdlog::debug("keyframe {}: {} recent points observed after the fact", keyframe->id(), observed);
}

void LocalMapper::cullRecentPoints(KeyFrame* keyframe) {
  // A new point must be found in at least a quarter of the frames that should see it, and, once
  // two keyframes have passed, be seen by enough keyframes.
  const int min_observations = options_.monocular ? 2 : 3;
  const KeyFrameId current = keyframe->id();
  std::size_t culled = 0;
  for (auto it = recent_points_.begin(); it != recent_points_.end();) {
    MapPoint* p = *it;
    const KeyFrameId born = p->firstKeyFrameId();
    const std::uint64_t age = (current & 0x00FFFFFFFFFFFFFF) - (born & 0x00FFFFFFFFFFFFFF);
    if (p->isBad()) {
      it = recent_points_.erase(it);
    } else if (idOrigin(born) != idOrigin(current)) {
      ++it;  // another client's: its age counts in that client's keyframes
    } else if (p->foundRatio() < 0.25f || (age >= 2 && p->observationCount() <= min_observations)) {
      map_.erasePoint(p);
      ++culled;
      it = recent_points_.erase(it);
    } else if (age >= 3) {
      it = recent_points_.erase(it);
    } else {
      ++it;
    }
  }
  MutexLock lock(stats_mutex_);
  stats_.points_culled += culled;
}

void LocalMapper::createNewPoints(KeyFrame* keyframe) {
  const bool mono = options_.monocular;
  std::vector<KeyFrame*> neighbours;
  {
    MutexLock lock(map_.updateMutex());
    if (keyframe->isBad()) return;
    neighbours = keyframe->bestCovisibles(mono ? options_.triangulation_neighbours_mono
                                               : options_.triangulation_neighbours_depth);
  }
  // Neighbours normally were described when they were mapped; keyframes made before the
  // vocabulary was given are described now.
  for (KeyFrame* neighbour : neighbours) describe(neighbour);
  std::size_t searches = 0, bow_searches = 0, proposed = 0;
  double search_ms = 0.0;
  const FrameFeatures& f1 = keyframe->features();
  std::size_t created = 0;

  for (KeyFrame* neighbour : neighbours) {
    if (hasPending(keyframe) && created > 0) break;
    MutexLock lock(map_.updateMutex());
    if (neighbour->isBad() || keyframe->isBad()) continue;
    const Eigen::Vector3d c1 = keyframe->cameraCenter();
    const Eigen::Vector3d c2 = neighbour->cameraCenter();
    const double baseline = (c2 - c1).norm();
    if (mono) {
      const double depth = neighbour->medianSceneDepth();
      if (depth <= 0.0 || baseline / depth < 0.01) continue;
    } else if (f1.bf > 0.f && baseline < f1.bf / camera_.fx()) {
      continue;
    }
    const auto search_start = std::chrono::steady_clock::now();
    const bool by_bow = searchesByBow() && canMatchForTriangulationByBow(*keyframe, *neighbour);
    const auto pairs = by_bow ? matchForTriangulationByBow(*keyframe, *neighbour, camera_, mono,
                                                           options_.triangulation_ratio)
                              : matchForTriangulation(*keyframe, *neighbour, camera_, mono,
                                                      options_.triangulation_ratio);
    search_ms +=
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - search_start)
            .count();
    ++searches;
    bow_searches += by_bow ? 1 : 0;
    proposed += pairs.size();
    for (const auto& [index, point] : createPointsFromPairs(
             map_, keyframe, neighbour, pairs, camera_, options_.min_triangulation_parallax_deg)) {
      recent_points_.push_back(point);
      ++created;
    }
  }
  spdlog::debug("keyframe {} (frame {}): {} new points from {} pairs with {} neighbours",
                keyframe->id(), keyframe->frameIndex(), created, proposed, neighbours.size());
  MutexLock lock(stats_mutex_);
  stats_.points_created += created;
  stats_.triangulation_searches += searches;
  stats_.triangulation_bow_searches += bow_searches;
  stats_.triangulation_pairs += proposed;
  stats_.triangulation_search_ms += search_ms;
}

void LocalMapper::fuseWithNeighbours(KeyFrame* keyframe) {
  MutexLock lock(map_.updateMutex());
  if (keyframe->isBad()) return;
  const std::size_t n =
      options_.monocular ? options_.fusion_neighbours_mono : options_.fusion_neighbours_depth;
  std::vector<KeyFrame*> targets;
  for (KeyFrame* kf : keyframe->bestCovisibles(n)) {
    if (kf->isBad() || kf->fuse_target_for == keyframe->id()) continue;
    kf->fuse_target_for = keyframe->id();
    targets.push_back(kf);
    for (KeyFrame* kf2 : kf->bestCovisibles(5)) {
      if (kf2->isBad() || kf2 == keyframe || kf2->fuse_target_for == keyframe->id()) continue;
      kf2->fuse_target_for = keyframe->id();
      targets.push_back(kf2);
    }
  }
  // The keyframe's points into its neighbours, then the neighbours' points into the keyframe.
  const std::vector<MapPoint*> own = keyframe->goodPoints();
  for (KeyFrame* target : targets) fuse(map_, target, own, camera_);
  std::vector<MapPoint*> theirs;
  for (KeyFrame* target : targets) {
    for (MapPoint* p : target->goodPoints()) {
      if (p->fuse_candidate_for == keyframe->id()) continue;
      p->fuse_candidate_for = keyframe->id();
      theirs.push_back(p);
    }
  }
  fuse(map_, keyframe, theirs, camera_);
  for (MapPoint* p : keyframe->goodPoints()) map_.refreshPoint(p);
  map_.updateConnections(keyframe);
}

KeyFrameRedundancy LocalMapper::redundancy(const KeyFrame& kf) const {
  const FrameFeatures& f = kf.features();
  const float close_depth = 40.f * f.bf / static_cast<float>(camera_.fx());
  KeyFrameRedundancy r;
  for (std::size_t i = 0; i < kf.size(); ++i) {
    MapPoint* p = kf.point(i);
    if (p == nullptr || p->isBad()) continue;
    // With depth, only close points (those measured well by it) count.
    if (!options_.monocular && (!f.hasDepth(i) || f.depth[i] > close_depth)) continue;
    ++r.points;
    if (p->observations().size() <= 3) continue;
    const int level = f.keypoints[i].octave;
    int seen_by = 0;
    for (const auto& [id, obs] : p->observations()) {
      if (obs.keyframe == &kf) continue;
      if (obs.keyframe->features().keypoints[obs.index].octave <= level + 1 && ++seen_by >= 3) {
        break;
      }
    }
    if (seen_by >= 3) ++r.redundant;
  }
  return r;
}

bool LocalMapper::cullRevisit(KeyFrame* keyframe) {
  MutexLock lock(map_.updateMutex());
  if (keyframe->isBad() || keyframe == map_.originKeyFrame() || keyframe->isProtected()) {
    return false;
  }
  const double depth = keyframe->medianSceneDepth();
  if (!(depth > 0.0)) return false;
  const double max_distance = options_.revisit_distance_ratio * depth;
  const double min_cos = std::cos(options_.revisit_max_angle_deg * M_PI / 180.0);
  const Eigen::Vector3d axis = keyframe->poseInverse().rotation() * Eigen::Vector3d::UnitZ();
  for (KeyFrame* older :
       keyframe->covisiblesWithWeightAtLeast(options_.revisit_min_shared_points)) {
    // Another client's keyframe is a revisit whatever its frame number (each client counts its
    // own frames).
    const bool same_client = idOrigin(older->id()) == idOrigin(keyframe->id());
    if (older->isBad() || (same_client && older->frameIndex() + options_.revisit_min_frames >
                                              keyframe->frameIndex())) {
      continue;
    }
    if ((older->cameraCenter() - keyframe->cameraCenter()).norm() > max_distance) continue;
    const Eigen::Vector3d older_axis = older->poseInverse().rotation() * Eigen::Vector3d::UnitZ();
    if (older_axis.dot(axis) < min_cos) continue;
    spdlog::debug(
        "keyframe of frame {} culled on a revisit: frame {}'s keyframe saw the same ({} "
        "points shared, {:.3f} apart)",
        keyframe->frameIndex(), older->frameIndex(), keyframe->weight(older),
        (older->cameraCenter() - keyframe->cameraCenter()).norm());
    map_.eraseKeyFrame(keyframe, older);
    MutexLock stats_lock(stats_mutex_);
    ++stats_.keyframes_culled;
    ++stats_.revisit_keyframes_culled;
    return true;
  }
  return false;
}

void LocalMapper::cullKeyFrames(KeyFrame* keyframe) {
  // A keyframe is redundant when 90 % of its points are seen, at the same or a finer scale, by at
  // least three other keyframes.
  MutexLock lock(map_.updateMutex());
  if (keyframe->isBad()) return;
  std::size_t culled = 0;
  double best = 0.0;
  std::size_t checked = 0;
  for (KeyFrame* kf : keyframe->bestCovisibles(static_cast<std::size_t>(-1))) {
    if (kf->isBad() || kf == map_.originKeyFrame() || kf->isProtected()) continue;
    const KeyFrameRedundancy r = redundancy(*kf);
    ++checked;
    if (r.points > 0) best = std::max(best, static_cast<double>(r.redundant) / r.points);
    if (r.points > 0 && r.redundant > options_.redundant_ratio * r.points) {
      map_.eraseKeyFrame(kf);
      ++culled;
    }
  }
  spdlog::debug("keyframe culling at frame {}: {} covisibles checked, best ratio {:.2f}, {} culled",
                keyframe->frameIndex(), checked, best, culled);
  MutexLock stats_lock(stats_mutex_);
  stats_.keyframes_culled += culled;
}

}  // namespace edgeslam
