#pragma once
// Writes one session's map into the store as it changes, off the mapping and tracking threads:
// the changes noted (MapChangeObserver) are gathered and, about once a second, the map's current
// state of what changed is copied under the map's mutex and written as one transaction on the
// writer's own thread. A killed process loses at most the last interval.
#include <condition_variable>
#include <memory>
#include <thread>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "map/map.h"
#include "map/map_change_observer.h"
#include "store/map_store.h"
#include "util/mutex.h"
#include "util/timing_stats.h"

namespace edgeslam {

class MapStoreWriter;

// The writers of a process (shared by its sessions; thread-safe): what they wrote, and a way to
// have every live one write what it has now (before a run reports its figures).
class MapStoreWriteStats {
 public:
  void addBatch(std::size_t keyframes, std::size_t points, std::size_t points_moved, double copy_ms,
                double write_ms);
  void addFailure();
  void attach(MapStoreWriter* writer);
  void detach(MapStoreWriter* writer);
  void flushAll();
  struct Totals {
    std::uint64_t batches = 0;
    std::uint64_t keyframes_written = 0;
    std::uint64_t points_written = 0;  // whole
    std::uint64_t points_moved = 0;    // position updates only
    std::uint64_t failures = 0;
    PercentileSummary write_ms;  // per batch, the store's transaction
    PercentileSummary copy_ms;   // per batch, the copy under the map's mutex
  };
  Totals totals() const;

 private:
  mutable Mutex mutex_;
  Mutex writers_mutex_;  // held while the writers flush
  std::vector<MapStoreWriter*> writers_ GUARDED_BY(writers_mutex_);
  Totals totals_ GUARDED_BY(mutex_);
  SampleStats write_ms_ GUARDED_BY(mutex_);
  SampleStats copy_ms_ GUARDED_BY(mutex_);
};

class MapStoreWriter : public MapChangeObserver {
 public:
  MapStoreWriter(std::shared_ptr<MapStore> store, StoreSessionId session, const Map& map,
                 std::shared_ptr<MapStoreWriteStats> stats, double interval_s = 1.0);
  ~MapStoreWriter() override;
  MapStoreWriter(const MapStoreWriter&) = delete;
  MapStoreWriter& operator=(const MapStoreWriter&) = delete;

  void onMapCleared() override;
  void onMapChanged(const MapChanges& changes) override;
  void onMasks(const std::vector<MaskRecord>& masks) override;

  // The session resumes a stored one: these keyframes are in the store already (later changes
  // update their poses or delete them instead of writing them whole). Call before any change.
  void assumeStored(const std::vector<KeyFrameId>& keyframes);
  // Stored keyframes whose place (bag of words, direct index) the store lacks (a store of schema
  // version 1): each is written once the keyframe has one.
  void storePlacesOf(const std::vector<KeyFrameId>& keyframes);

  // Writes what is pending now (on the caller's thread) and waits for it.
  void flush() EXCLUDES(write_mutex_, pending_mutex_);
  // Writes the rest, marks the session ended and stops the thread. Call before the map goes.
  void stop() EXCLUDES(write_mutex_, pending_mutex_);

 private:
  void run() EXCLUDES(write_mutex_, pending_mutex_);
  MapStoreBatch takeBatch() REQUIRES(write_mutex_) EXCLUDES(pending_mutex_);
  // The keyframe's place as a record; false while it has none.
  bool addPlace(const KeyFrame& keyframe, MapStoreBatch& batch) REQUIRES(write_mutex_);

  std::shared_ptr<MapStore> store_;
  StoreSessionId session_;
  const Map& map_;
  std::shared_ptr<MapStoreWriteStats> stats_;
  double interval_s_;

  Mutex pending_mutex_;
  std::condition_variable wake_;
  bool stopping_ GUARDED_BY(pending_mutex_) = false;
  bool cleared_ GUARDED_BY(pending_mutex_) = false;
  // Created, changed or erased since the last batch.
  std::unordered_set<KeyFrameId> keyframes_ GUARDED_BY(pending_mutex_);
  std::unordered_set<MapPointId> points_ GUARDED_BY(pending_mutex_);  // written whole
  // Only moved (and not in points_).
  std::unordered_set<MapPointId> points_moved_ GUARDED_BY(pending_mutex_);
  std::vector<MaskRecord> masks_ GUARDED_BY(pending_mutex_);

  Mutex write_mutex_;  // one batch at a time
  std::unordered_set<KeyFrameId> stored_keyframes_ GUARDED_BY(write_mutex_);
  // Stored keyframes not described yet when they were written.
  std::unordered_set<KeyFrameId> awaiting_place_ GUARDED_BY(write_mutex_);
  std::unordered_map<const Vocabulary*, std::uint64_t> vocabulary_checksums_
      GUARDED_BY(write_mutex_);
  bool stopped_ GUARDED_BY(write_mutex_) = false;
  std::thread thread_;
};

}  // namespace edgeslam
