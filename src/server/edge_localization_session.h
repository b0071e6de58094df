#pragma once
// A localise-only client's session on the edge (issue 20, "localisation only"): a stored map,
// loaded read-only, that the client localises in without changing it. The client's questions come
// as localization_query uploads. A lost frame (keypoints, no parent) is relocalised against the
// whole map: bag-of-words candidates, PnP RANSAC, pose refinement. A tracked frame (the stored
// keyframe it tracks against as parent) moves the client's map window there. Each is answered by
// a slice that carries the window's keyframes and points the client lacks and the answer itself.
// Nothing is mapped, culled or written.
#include <cstdint>
#include <functional>
#include <memory>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_records.h"
#include "place/vocabulary.h"
#include "relocalize/frame_relocalization.h"
#include "relocalize/keyframe_places.h"
#include "server/client_map_window.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"
#include "util/timing_stats.h"

namespace edgeslam {

struct EdgeLocalizationSessionOptions {
  std::shared_ptr<const Vocabulary> vocabulary;  // required: the whole-map place search
  // The keyframes the client holds around where it was found. A client that asks for an unbounded
  // map gets this many; its whole first window comes in the first answer.
  std::size_t window_keyframes = 20;
  std::size_t relocalization_candidates = 10;
  // The edge has the time a client's frame does not: a wider budget than the tracker's 25 ms.
  FrameRelocalizationOptions relocalization{
      .budget_ms = 80.0, .min_matches = 15, .min_inliers = 50};
};

struct EdgeLocalizationStats {
  std::uint64_t queries = 0;
  std::uint64_t relocalization_queries = 0;  // lost frames asked about
  std::uint64_t relocalized = 0;             // of those, found
  std::uint64_t window_moves = 0;            // tracked frames' window updates
  std::uint64_t slices = 0;
  std::uint64_t keyframes_sent = 0;
  SampleStats relocalization_ms;
};

class EdgeLocalizationSession {
 public:
  using Publish = std::function<void(MapSlice)>;

  // `load` fills the empty map (it takes the map's mutex itself); the keyframes it leaves are
  // filed for place recognition with their stored bags of words where they carry some. Throws
  // std::invalid_argument without a vocabulary or when the map has no keyframes.
  EdgeLocalizationSession(const PinholeCamera& camera, EdgeLocalizationSessionOptions options,
                          const std::function<void(Map&)>& load, Publish publish);

  // Answers a localization_query upload (on the caller's thread). Throws std::invalid_argument
  // for an upload that is not one, or whose features do not fit the camera.
  void onQuery(const KeyFrameUpload& upload) EXCLUDES(map_.updateMutex());
  // The client lost its map (a reconnection): it gets an empty full resync and asks again; the
  // window starts empty.
  void publishFullResync() EXCLUDES(map_.updateMutex());

  EdgeLocalizationStats stats() const;
  std::size_t keyFrameCount() const;
  const Map& map() const { return map_; }

 private:
  void publish(MapSlice slice) EXCLUDES(map_.updateMutex());

  PinholeCamera camera_;
  EdgeLocalizationSessionOptions options_;
  Map map_;
  std::unique_ptr<KeyFramePlaces> places_ GUARDED_BY(map_.updateMutex());
  ClientMapWindow window_ GUARDED_BY(map_.updateMutex());
  Publish publish_;
  mutable Mutex state_mutex_;
  std::uint64_t slice_sequence_ GUARDED_BY(state_mutex_) = 0;
  EdgeLocalizationStats stats_ GUARDED_BY(state_mutex_);
};

}  // namespace edgeslam
