#pragma once
// Matching that needs map types: map points (with their scale range and viewing direction) against
// frame or keyframe features, by projection or by descriptor, plus the epipolar search for
// triangulation and point fusion. Pure functions over Frame / KeyFrame / Map; callers hold the
// map's update mutex.
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
// track_* scratch fields (projection, predicted level, view cosine, track_in_view = true).
bool isInFrustum(MapPoint* point, const Frame& frame, float min_view_cos = 0.5f);

// Motion-model tracking: projects the points matched in `last` into `current` (whose T_cw must be
// set to the predicted pose) and searches a window of `radius` * scale(level) around each
// projection, at levels near the one the point had in `last` (for RGB-D/stereo, `monocular` = false
// also uses the forward/backward motion to bound the level). Hamming <= kMatchDistanceHigh,
// rotation check. Fills current.points for new matches; returns how many.
int matchByProjection(Frame& current, const Frame& last, float radius, bool monocular);

// Local-map tracking: for each point with track_in_view (see isInFrustum) not yet matched in
// `frame`, search a window around its projection scaled by `radius_factor`, the predicted level's
// scale and the viewing angle (wider when the view cosine is below 0.998), at predicted level
// -1..+0; best and second best with ratio `ratio` when on the same level; Hamming <=
// kMatchDistanceHigh. Returns the number of new matches.
int matchLocalPoints(Frame& frame, const std::vector<MapPoint*>& points, float radius_factor,
                     float ratio = 0.8f);

// Reference-keyframe tracking without a pose prior: every good map point of `keyframe` against
// every feature of `frame` by descriptor (Hamming <= kMatchDistanceLow, ratio 0.7, rotation check).
// Writes frame.points for the matched keypoints (overwriting); returns the number of matches.
int matchKeyFrameByDescriptor(const KeyFrame& keyframe, Frame& frame, float ratio = 0.7f);

// Relocalisation refinement: projects the keyframe's good points not in `already_matched` into
// `frame` (T_cw set), window `radius` * scale, Hamming <= max_distance; returns new matches.
int matchKeyFrameByProjection(Frame& frame, const KeyFrame& keyframe,
                              const std::vector<MapPoint*>& already_matched, float radius,
                              int max_distance);

// New-point search between two keyframes: pairs of keypoints that have no map point yet, whose
// descriptors match (Hamming <= kMatchDistanceLow, rotation check) and that satisfy the epipolar
// constraint of the fundamental matrix implied by the two poses (squared distance to the epipolar
// line below 3.84 * sigma^2 of kf2's level); candidates within 10 px * scale of the epipole in kf2
// are skipped unless one side has sensor depth (and never for `monocular`). The ratio test is
// between the best and second best keypoint inside the epipolar band. At most one pair per kf2
// keypoint (the closest descriptor). Without bag-of-words yet, every unmatched kf1 keypoint is
// tested against the band of kf2's unmatched keypoints. Returns (index in kf1, index in kf2)
// pairs, sorted.
std::vector<std::pair<std::size_t, std::size_t>> matchForTriangulation(const KeyFrame& kf1,
                                                                       const KeyFrame& kf2,
                                                                       const PinholeCamera& camera,
                                                                       bool monocular,
                                                                       float ratio = 0.6f);

// Fusion of duplicated points: projects `points` into `keyframe`, searches a window of `radius` *
// scale(predicted level) (with a reprojection chi-square check at 5.99 mono / 7.8 with depth);
// when the best keypoint already has a point the one with more observations replaces the other,
// otherwise the point gains an observation. All changes go through `map`. Returns the number fused.
int fuse(Map& map, KeyFrame* keyframe, const std::vector<MapPoint*>& points,
         const PinholeCamera& camera, float radius = 3.0f);

}  // namespace edgeslam
