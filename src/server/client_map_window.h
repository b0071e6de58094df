#pragma once
// The part of the global map a client with a bounded map holds (paper Sec. V: the client's local
// map database is about a tenth of the global one). The edge chooses it, because it has the whole
// covisibility graph: around the client's latest mapped keyframe, its strongest covisibility
// neighbourhood plus the most recent keyframes. Each slice then carries the keyframes (and their
// points) that entered the window and the client does not hold, the held keyframes that left a
// larger window (hysteresis: a keyframe at the border does not come and go every slice), and only
// the point records the client can attach to a keyframe it holds. All calls under the map's
// update mutex.
#include <cstddef>
#include <set>
#include <vector>

#include "map/map.h"
#include "map/map_records.h"

namespace edgeslam {

struct ClientMapWindowOptions {
  std::size_t keyframes = 0;  // the window; 0 = unbounded (nothing is evicted or filtered)
  // A held keyframe is evicted only when outside the window grown to this many times its size.
  double keep_factor = 1.5;
  // Part of the window given to the most recent keyframes whatever their covisibility.
  double recent_share = 0.25;
  // Keyframes sent back into the window per slice at most (the closest first), to spread the
  // traffic of a revisit over a few slices.
  std::size_t max_entering_per_slice = 10;
};

// Up to `count` keyframes around `centre`: the centre, the `recent` highest ids of the centre's
// origin (its client's most recent), then
// their covisibility neighbourhood breadth first, each keyframe's links strongest first.
// Deterministic, and a shorter list is a prefix of a longer one.
std::vector<KeyFrame*> keyFrameNeighbourhood(const Map& map, KeyFrame* centre, std::size_t count,
                                             std::size_t recent) REQUIRES(map.updateMutex());

class ClientMapWindow {
 public:
  explicit ClientMapWindow(ClientMapWindowOptions options = {});

  bool bounded() const { return options_.keyframes > 0; }
  const ClientMapWindowOptions& options() const { return options_; }
  std::size_t keepSize() const;
  std::size_t recentCount() const;

  // The client made this keyframe (an upload): it holds it.
  void clientHolds(KeyFrameId id) { held_.insert(id); }
  // The client emptied its map.
  void clear() { held_.clear(); }
  bool holds(KeyFrameId id) const { return held_.contains(id); }
  const std::set<KeyFrameId>& held() const { return held_; }

  // Bounds `slice` (built from the map's changes) to the window around `centre` (nullptr: no
  // window update, only the filtering): adds records of keyframes entering the window and of the
  // points they see that the client lacks, lists the evicted keyframes, and drops point records
  // and moves of points no held keyframe sees. Keyframe poses and erasures are left for every
  // keyframe: the client keeps evicted keyframes' poses. No-op when unbounded.
  void shape(const Map& map, KeyFrame* centre, MapSlice& slice) REQUIRES(map.updateMutex());

 private:
  bool seenByHeld(const MapPoint& point) const;

  ClientMapWindowOptions options_;
  std::set<KeyFrameId> held_;
};

}  // namespace edgeslam
