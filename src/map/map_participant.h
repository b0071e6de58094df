#pragma once
// A thread that keeps pointers to map elements from one hold of the map's updateMutex() to the
// next: tracking (its last frame, its local map), local mapping (its recent points), loop closing,
// a global bundle adjustment. The map frees an erased point, and the features of an erased
// keyframe, only once every participant has declared a quiescent point after the erasure: a point
// at which it keeps no pointer to an erased element. A thread that lets go of every pointer
// before it releases the mutex need not participate.
//
// Erased keyframes themselves stay (pose and spanning-tree place, a few hundred bytes): a frame's
// pose is kept relative to a keyframe that may be erased later, and follows it through the tree.
#include <cstdint>
#include <string>

#include "map/map.h"
#include "util/thread_annotations.h"

namespace edgeslam {

class MapParticipant {
 public:
  // Both take the map's mutex: not while holding it.
  MapParticipant(Map& map, std::string name) EXCLUDES(map.updateMutex());
  ~MapParticipant();
  MapParticipant(const MapParticipant&) = delete;
  MapParticipant& operator=(const MapParticipant&) = delete;

  // The caller holds the map's updateMutex() and has dropped every pointer it keeps to an erased
  // element (it may go on keeping pointers to live ones). Frees what no participant can reach.
  // `map` is the map this participates in (std::logic_error otherwise): named by the caller so
  // that the compiler sees the caller's lock is that map's.
  void quiescent(Map& map) REQUIRES(map.updateMutex());

  const std::string& name() const { return name_; }

 private:
  friend class Map;
  Map& map_;
  std::string name_;
  // Erasures 1..safe_through_ are out of this participant's reach.
  std::uint64_t safe_through_ = 0;
};

}  // namespace edgeslam
