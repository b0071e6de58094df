#pragma once
// Between map elements and their wire records, both ways. The callers hold the map's update mutex.
#include <memory>
#include <unordered_set>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_records.h"

namespace edgeslam {

KeyFrameFeaturesRecord featuresRecord(const FrameFeatures& features);
// Rebuilds scales and the search grid; throws std::invalid_argument when the arrays disagree.
std::shared_ptr<FrameFeatures> featuresFromRecord(const KeyFrameFeaturesRecord& record,
                                                  const PinholeCamera& camera);

KeyFrameRecord keyFrameRecord(const KeyFrame& keyframe);
MapPointRecord mapPointRecord(const MapPoint& point);
KeyFramePoseRecord keyFramePoseRecord(const KeyFrame& keyframe);

// Creates the keyframe with the record's id (or returns the existing one; an evicted one gets the
// record's features and pose back) and links the keypoints whose point ids the map already has.
// Points named but unknown are left for the caller.
KeyFrame* insertKeyFrameRecord(Map& map, const KeyFrameRecord& record, const PinholeCamera& camera);

// Creates or updates a point so that its position, appearance and its observations among the
// keyframes this map has match the record. Observations in keyframes newer than
// `newest_known_to_sender` (same id origin) are kept: the sender could not know them. Observations
// in evicted keyframes are not held. Returns nullptr when none of the observing keyframes is here
// (nothing to attach it to).
MapPoint* upsertPointRecord(Map& map, const MapPointRecord& record,
                            KeyFrameId newest_known_to_sender);

// Uploads of RGB-D keyframes. The sender flags a new point whose position is the back-projection
// of its first observation in `keyframe` (within 0.1 mm), so that the wire can leave it out...
bool isDepthBackProjection(const MapPoint& point, const KeyFrame& keyframe,
                           const PinholeCamera& camera);
// ...and the receiver rebuilds the flagged positions from the keyframe as it arrived. Throws
// std::invalid_argument when a flagged point's first observation is not a keypoint with depth of
// `keyframe`.
void rebuildPositionsFromDepth(std::vector<MapPointRecord>& points, const KeyFrameRecord& keyframe,
                               const PinholeCamera& camera);

}  // namespace edgeslam
