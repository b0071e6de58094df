#pragma once
// Between map elements and their wire records, both ways. The callers hold the map's update mutex.
#include <memory>
#include <optional>
#include <unordered_set>
#include <vector>

#include "geometry/camera.h"
#include "map/map.h"
#include "map/map_records.h"

namespace edgeslam {

KeyFrameFeaturesRecord featuresRecord(const FrameFeatures& features);
// Rebuilds scales and the search grid; throws std::invalid_argument when the arrays disagree.
std::shared_ptr<FrameFeatures> featuresFromRecord(const KeyFrameFeaturesRecord& record,
                                                  const PinholeCamera& camera);
// The same, taking the keypoints, descriptors and depths out of `record` (left empty) instead of
// copying them.
std::shared_ptr<FrameFeatures> featuresFromRecord(KeyFrameFeaturesRecord&& record,
                                                  const PinholeCamera& camera);

KeyFrameRecord keyFrameRecord(const KeyFrame& keyframe);
MapPointRecord mapPointRecord(const MapPoint& point);
KeyFramePoseRecord keyFramePoseRecord(const KeyFrame& keyframe);

// Creates the keyframe with the record's id (or returns the existing one; an evicted one gets the
// record's features and pose back) and links the keypoints whose point ids the map already has.
// Points named but unknown are left for the caller.
KeyFrame* insertKeyFrameRecord(Map& map, const KeyFrameRecord& record, const PinholeCamera& camera)
    REQUIRES(map.updateMutex());

// Creates or updates a point so that its position, appearance and its observations among the
// keyframes this map has match the record. Observations in keyframes newer than
// `newest_known_to_sender` (same id origin) are kept: the sender could not know them. Observations
// in evicted keyframes are not held, nor those on a keypoint that holds a point this side made in
// a keyframe newer than `newest_known_to_sender` (the sender will settle that clash). Returns
// nullptr when none of the observing keyframes is here (nothing to attach it to).
MapPoint* upsertPointRecord(Map& map, const MapPointRecord& record,
                            KeyFrameId newest_known_to_sender) REQUIRES(map.updateMutex());

// A new point of a client's keyframe upload, on the edge. The point may be seen in older keyframes
// of the client too (monocular clients triangulate with their neighbours), which the edge may have
// changed since the client saw them: such a keypoint may hold a point of the edge's own (mapped
// before the client had it) or the keyframe may be gone. Those observations are not applied (the
// edge's point keeps its keypoint), and what differs from the client's map is returned, to be
// settled by resolveUploadedPointConflicts once the map records changes again. Call with change
// recording off (the client has what it sent); refreshes the point. nullopt: applied as sent (or
// not attached at all, as upsertPointRecord).
struct UploadedPointConflict {
  MapPoint* point = nullptr;     // as applied
  MapPoint* occupant = nullptr;  // the edge's point on one of its keypoints, if any
};
std::optional<UploadedPointConflict> insertUploadedPoint(Map& map, const MapPointRecord& record,
                                                         KeyFrameId uploaded_keyframe)
    REQUIRES(map.updateMutex());
// With change recording on: a point whose keypoint held another point merges into that one
// (Map::replacePoint, as fusion would); one that only lost observations is erased when that left
// it as weak as Map::eraseObservation would (the client erases it then) or sent again.
void resolveUploadedPointConflicts(Map& map, const std::vector<UploadedPointConflict>& conflicts)
    REQUIRES(map.updateMutex());

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
