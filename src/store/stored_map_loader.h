#pragma once
// A stored session back into a Map, as a server resuming it would hold it: keyframes with their
// features and poses, points with their observations and appearance; the covisibility graph and
// spanning tree are rebuilt from the shared points (the stored parents are for exports). Bags of
// words and direct indices (places) are stored from schema version 2 on and attached when they
// were made by the vocabulary in use; local mapping computes the others from the descriptors.
#include <cstdint>
#include <memory>
#include <vector>

#include "map/map.h"
#include "place/vocabulary.h"
#include "store/map_store.h"

namespace edgeslam {

// The session a map is resumed or localised in: the latest one with keyframes (each stored session
// is in its own frame). nullptr when none has keyframes.
StoredSession* latestSessionWithKeyFrames(StoredMap& map);

// Into an empty map. Throws StoreError when the records contradict themselves.
void loadStoredSession(const StoredSession& session, Map& map) EXCLUDES(map.updateMutex());
// The same, moving each keyframe's features out of its record instead of copying them (the
// records keep their ids, poses and point ids; the places are untouched): for a caller done with
// the features, which spares a 1000-keyframe map ~90 MB of copies.
void loadStoredSessionTakingFeatures(StoredSession& session, Map& map) EXCLUDES(map.updateMutex());

struct AttachedPlaces {
  std::size_t attached = 0;
  std::vector<KeyFrameId> missing;  // keyframes of the map left without a place
};

// After loadStoredSession: each keyframe takes its stored place when `vocabulary` (whose
// checksum() is `checksum`, computed once by the caller) made it at `direct_index_depth`. Throws
// StoreError when a stored place names words or nodes the vocabulary does not have.
AttachedPlaces attachStoredPlaces(const StoredSession& session, Map& map,
                                  const Vocabulary& vocabulary, std::uint64_t checksum,
                                  int direct_index_depth) EXCLUDES(map.updateMutex());

// The keyframes' places as local mapping makes them (LocalMapper::describe), for those without
// one; returns how many were computed.
std::size_t describeKeyFrames(Map& map, const Vocabulary& vocabulary, int direct_index_depth)
    EXCLUDES(map.updateMutex());

}  // namespace edgeslam
