#pragma once
// A stored session back into a Map, as a server resuming it would hold it: keyframes with their
// features and poses, points with their observations and appearance; the covisibility graph and
// spanning tree are rebuilt from the shared points (the stored parents are for exports). Bags of
// words are not stored either: local mapping computes a keyframe's from its descriptors when it
// needs it.
#include "map/map.h"
#include "store/map_store.h"

namespace edgeslam {

// Into an empty map. Throws StoreError when the records contradict themselves.
void loadStoredSession(const StoredSession& session, Map& map);

}  // namespace edgeslam
