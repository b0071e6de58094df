#include "store/map_store_writer.h"

#include <spdlog/spdlog.h>

#include <chrono>

#include "map/map_replication.h"
#include "place/vocabulary.h"

namespace edgeslam {

void MapStoreWriteStats::addBatch(std::size_t keyframes, std::size_t points,
                                  std::size_t points_moved, double copy_ms, double write_ms) {
  MutexLock lock(mutex_);
  ++totals_.batches;
  totals_.keyframes_written += keyframes;
  totals_.points_written += points;
  totals_.points_moved += points_moved;
  write_ms_.add(write_ms);
  copy_ms_.add(copy_ms);
}

void MapStoreWriteStats::addFailure() {
  MutexLock lock(mutex_);
  ++totals_.failures;
}

void MapStoreWriteStats::attach(MapStoreWriter* writer) {
  MutexLock lock(writers_mutex_);
  writers_.push_back(writer);
}

void MapStoreWriteStats::detach(MapStoreWriter* writer) {
  MutexLock lock(writers_mutex_);
  std::erase(writers_, writer);
}

void MapStoreWriteStats::flushAll() {
  MutexLock lock(writers_mutex_);
  for (MapStoreWriter* writer : writers_) writer->flush();
}

MapStoreWriteStats::Totals MapStoreWriteStats::totals() const {
  MutexLock lock(mutex_);
  Totals out = totals_;
  out.write_ms = write_ms_.summary();
  out.copy_ms = copy_ms_.summary();
  return out;
}

MapStoreWriter::MapStoreWriter(std::shared_ptr<MapStore> store, StoreSessionId session,
                               const Map& map, std::shared_ptr<MapStoreWriteStats> stats,
                               double interval_s)
    : store_(std::move(store)),
      session_(session),
      map_(map),
      stats_(std::move(stats)),
      interval_s_(interval_s) {
  if (stats_) stats_->attach(this);
  thread_ = std::thread([this] { run(); });
}

MapStoreWriter::~MapStoreWriter() {
  stop();
}

void MapStoreWriter::assumeStored(const std::vector<KeyFrameId>& keyframes) {
  MutexLock writing(write_mutex_);
  stored_keyframes_.insert(keyframes.begin(), keyframes.end());
}

void MapStoreWriter::storePlacesOf(const std::vector<KeyFrameId>& keyframes) {
  MutexLock writing(write_mutex_);
  awaiting_place_.insert(keyframes.begin(), keyframes.end());
}

bool MapStoreWriter::addPlace(const KeyFrame& keyframe, MapStoreBatch& batch) {
  const std::shared_ptr<const KeyFramePlace> place = keyframe.place();
  if (place == nullptr || place->vocabulary == nullptr) return false;
  auto checksum = vocabulary_checksums_.find(place->vocabulary);
  if (checksum == vocabulary_checksums_.end()) {
    checksum =
        vocabulary_checksums_.emplace(place->vocabulary, place->vocabulary->checksum()).first;
  }
  batch.places.push_back({.keyframe = keyframe.id(),
                          .vocabulary = checksum->second,
                          .direct_index_depth = place->direct_index_depth,
                          .bow = place->bow,
                          .features = place->features});
  return true;
}

void MapStoreWriter::onMapCleared() {
  MutexLock lock(pending_mutex_);
  cleared_ = true;
  keyframes_.clear();
  points_.clear();
  points_moved_.clear();
  masks_.clear();
}

void MapStoreWriter::onMapChanged(const MapChanges& changes) {
  MutexLock lock(pending_mutex_);
  for (const auto* ids :
       {&changes.keyframes_created, &changes.keyframes_updated, &changes.keyframes_erased}) {
    keyframes_.insert(ids->begin(), ids->end());
  }
  for (const auto* ids :
       {&changes.points_created, &changes.points_updated, &changes.points_erased}) {
    for (const MapPointId id : *ids) {
      points_.insert(id);
      points_moved_.erase(id);
    }
  }
  // Bundle adjustment moves many points at a time: those are updated in place, not rewritten.
  for (const MapPointId id : changes.points_moved) {
    if (!points_.contains(id)) points_moved_.insert(id);
  }
}

void MapStoreWriter::onMasks(const std::vector<MaskRecord>& masks) {
  MutexLock lock(pending_mutex_);
  masks_.insert(masks_.end(), masks.begin(), masks.end());
}

MapStoreBatch MapStoreWriter::takeBatch() {
  MapStoreBatch batch;
  std::unordered_set<KeyFrameId> keyframes;
  std::unordered_set<MapPointId> points;
  std::unordered_set<MapPointId> points_moved;
  {
    MutexLock lock(pending_mutex_);
    batch.cleared = cleared_;
    cleared_ = false;
    keyframes.swap(keyframes_);
    points.swap(points_);
    points_moved.swap(points_moved_);
    batch.masks.swap(masks_);
  }
  if (batch.cleared) {
    stored_keyframes_.clear();
    awaiting_place_.clear();
  }
  // What the map holds now decides: an element changed and then erased is erased.
  MutexLock map_lock(map_.updateMutex());
  for (const KeyFrameId id : keyframes) {
    const KeyFrame* keyframe = map_.keyFrame(id);
    if (keyframe == nullptr || keyframe->isBad()) {
      if (stored_keyframes_.erase(id) > 0) batch.keyframes_erased.push_back(id);
    } else if (stored_keyframes_.insert(id).second) {
      batch.keyframes.push_back(keyFrameRecord(*keyframe));
      // Mapping describes a keyframe soon after it arrives: usually before this copy.
      if (!addPlace(*keyframe, batch)) awaiting_place_.insert(id);
    } else {
      batch.poses.push_back(keyFramePoseRecord(*keyframe));
    }
  }
  for (auto it = awaiting_place_.begin(); it != awaiting_place_.end();) {
    const KeyFrame* keyframe = map_.keyFrame(*it);
    if (keyframe == nullptr || keyframe->isBad() || !stored_keyframes_.contains(*it) ||
        addPlace(*keyframe, batch)) {
      it = awaiting_place_.erase(it);
    } else {
      ++it;
    }
  }
  for (const MapPointId id : points) {
    const MapPoint* point = map_.mapPoint(id);
    if (point == nullptr || point->isBad()) {
      batch.points_erased.push_back(id);
    } else {
      batch.points.push_back(mapPointRecord(*point));
    }
  }
  for (const MapPointId id : points_moved) {
    const MapPoint* point = map_.mapPoint(id);
    if (point == nullptr || point->isBad()) {
      batch.points_erased.push_back(id);
      continue;
    }
    MapPointRecord& moved = batch.points_moved.emplace_back();
    moved.id = id;
    moved.position = point->position();
    moved.normal = point->normal();
    moved.min_distance = point->baseMinDistance();
    moved.max_distance = point->baseMaxDistance();
  }
  return batch;
}

void MapStoreWriter::flush() {
  MutexLock writing(write_mutex_);
  if (stopped_) return;
  Stopwatch copy_timer;
  MapStoreBatch batch = takeBatch();
  const double copy_ms = copy_timer.elapsedMs();
  if (batch.empty()) return;
  Stopwatch write_timer;
  try {
    store_->write(session_, batch);
    if (stats_) {
      stats_->addBatch(batch.keyframes.size(), batch.points.size(), batch.points_moved.size(),
                       copy_ms, write_timer.elapsedMs());
    }
  } catch (const std::exception& e) {
    // The batch is lost (the transaction rolled back); later batches carry on so that at least
    // what changes again is kept. The keyframes it would have stored are sent in full again.
    for (const KeyFrameRecord& k : batch.keyframes) stored_keyframes_.erase(k.id);
    for (const KeyFramePlaceRecord& p : batch.places) awaiting_place_.insert(p.keyframe);
    if (stats_) stats_->addFailure();
    spdlog::error("map store: {}", e.what());
  }
}

void MapStoreWriter::run() {
  MutexLock lock(pending_mutex_);
  while (!stopping_) {
    lock.waitFor(wake_, std::chrono::duration<double>(interval_s_),
                 [this]() REQUIRES(pending_mutex_) { return stopping_; });
    if (stopping_) break;
    lock.unlock();
    flush();
    lock.lock();
  }
}

void MapStoreWriter::stop() {
  if (stats_) stats_->detach(this);
  {
    MutexLock lock(pending_mutex_);
    if (stopping_) return;
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  flush();
  MutexLock writing(write_mutex_);
  stopped_ = true;
  try {
    store_->endSession(session_);
  } catch (const std::exception& e) {
    spdlog::error("map store: {}", e.what());
  }
}

}  // namespace edgeslam
