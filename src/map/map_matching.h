#pragma once
// Matching that needs map types: map points (with their scale range and viewing direction) against
// frame or keyframe features, by projection or by descriptor, plus the epipolar search for
// triangulation and point fusion. Pure functions over Frame / KeyFrame / Map; callers hold the
// map's update mutex.
//
// Common rules: a frame slot that already holds a good (not bad) point is only overwritten by
// matchKeyFrameByDescriptor; bad points are skipped; projection matchers search with the point's
// representative descriptor in square windows (FeatureGrid); a frame lacking what a matcher needs
// (features whose sizes match points/outliers, camera, pose) gives std::invalid_argument naming
// the matcher and the frame.
#include <cstddef>
#include <utility>
#include <vector>

#include "features/descriptor_matching.h"
#include "geometry/camera.h"
#include "map/frame.h"
#include "map/keyframe.h"
#include "map/map.h"
#include "map/map_point.h"

namespace edgeslam {

// Whether `point` can be seen by `frame` at its current pose: in front of the camera, inside the
// undistorted image bounds, within the point's scale-invariance distance range and with a viewing
// angle whose cosine to the point's normal is at least `min_view_cos`. On success fills the point's
// track_* scratch fields (projection, predicted level, view cosine, track_in_view = true); on
// failure only clears track_in_view. Needs the frame's pose and camera.
bool isInFrustum(MapPoint* point, const Frame& frame, float min_view_cos = 0.5f);

// Motion-model tracking: projects the points matched in `last` (not flagged outliers) into
// `current` (whose T_cw must be set to the predicted pose) and searches a window of `radius` *
// scale(level) around each projection, at levels near the one the point had in `last` (for
// RGB-D/stereo, `monocular` = false also uses the forward/backward motion to bound the level).
// Where a candidate has depth, its virtual right coordinate must agree within the window.
// Hamming <= kMatchDistanceHigh, rotation check. Fills current.points for new matches; returns
// how many.
int matchByProjection(Frame& current, const Frame& last, float radius, bool monocular);

// Local-map tracking: for each point with track_in_view (see isInFrustum) not yet in
// frame.points, search a window around its projection scaled by `radius_factor`, the predicted
// level's scale and the viewing angle (wider when the view cosine is below 0.998), at predicted
// level -1..+0; best and second best with ratio `ratio` when on the same level; Hamming <=
// kMatchDistanceHigh; with depth and a pose, the right-coordinate check as above. Returns the
// number of new matches.
int matchLocalPoints(Frame& frame, const std::vector<MapPoint*>& points, float radius_factor,
                     float ratio = 0.8f);

// Reference-keyframe tracking without a pose prior: the keypoint descriptors of every good map
// point of `keyframe` against every feature of `frame` (Hamming <= kMatchDistanceLow, ratio,
// rotation check), brute force until bag-of-words arrives. One point per frame keypoint (the
// closest). Writes frame.points for the matched keypoints (overwriting those slots, leaving the
// others); returns the number of matches.
int matchKeyFrameByDescriptor(const KeyFrame& keyframe, Frame& frame, float ratio = 0.7f);

// Relocalisation refinement: projects the keyframe's good points not in `already_matched` (may
// hold nullptr) into `frame` (T_cw set), within their distance range, window `radius` *
// scale(predicted level), levels -1..+1, Hamming <= max_distance, rotation check; returns new
// matches.
int matchKeyFrameByProjection(Frame& frame, const KeyFrame& keyframe,
                              const std::vector<MapPoint*>& already_matched, float radius,
                              int max_distance);

// New-point search between two keyframes: pairs of keypoints that have no map point yet, whose
// descriptors match (Hamming <= kMatchDistanceLow, rotation check) and that satisfy the epipolar
// constraint of the fundamental matrix implied by the two poses (squared distance to the epipolar
// line below 3.84 * sigma^2 of kf2's level). kf2 keypoints within 10 px * scale of the epipole
// are skipped, unless `monocular` is false and either keypoint has sensor depth. The ratio test
// compares the best and second best kf2 keypoint inside the epipolar band (0.6 keeps ~93 % correct
// pairs on 7-Scenes; 0.8 gives ~60 % more pairs at ~90 %). At most one pair per kf2 keypoint (the
// closest descriptor). Every unmatched kf1 keypoint is tested against the band of kf2's unmatched
// keypoints (about 1.5 ms for 1000 x 1000). Returns (index in kf1,
// index in kf2) pairs, sorted.
std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulation(const KeyFrame& kf1,
                                                                       const KeyFrame& kf2,
                                                                       const PinholeCamera& camera,
                                                                       bool monocular,
                                                                       float ratio = 0.6f);

// The same search guided by bag of words: candidate pairs only between keypoints filed under the
// same node of the two keyframes' direct indexes (KeyFrame::place()), then the same checks
// (unmatched on both sides, Hamming <= kMatchDistanceLow, epipolar band, epipole rule, ratio
// against the second best candidate of the node inside the band, one pair per kf2 keypoint,
// rotation check). Compares a few keypoints per node instead of the whole band; misses pairs whose
// descriptors fall under different nodes. Falls back to matchForTriangulation when
// canMatchForTriangulationByBow is false. Throws std::invalid_argument when a direct index names
// a keypoint the keyframe does not have.
std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulationByBow(
    const KeyFrame& kf1, const KeyFrame& kf2, const PinholeCamera& camera, bool monocular,
    float ratio = 0.6f);
// Both keyframes have a place, from the same vocabulary with direct indexes at the same depth.
bool canMatchForTriangulationByBow(const KeyFrame& kf1, const KeyFrame& kf2);

// Fusion of duplicated points: projects `points` into `keyframe` (skipping those it already
// observes, outside their distance range or seen at more than 60 degrees from their normal),
// searches a window of `radius` * scale(predicted level) at levels -1..+0 (with a reprojection
// chi-square check at 5.99 mono / 7.8 with depth), Hamming <= kMatchDistanceLow. When the best
// keypoint already has a point the one with more observations replaces the other (a tie keeps the
// projected point), otherwise the point gains an observation and is refreshed. All changes go
// through `map`. Returns the number fused.
int fuse(Map& map, KeyFrame* keyframe, const std::vector<MapPoint*>& points,
         const PinholeCamera& camera, float radius = 3.0f) REQUIRES(map.updateMutex());

}  // namespace edgeslam
