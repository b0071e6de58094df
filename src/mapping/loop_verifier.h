#pragma once
// Geometric verification of loop candidates: bag-of-words matches between the current keyframe's
// points and those of a window around the candidate (the candidate and its best covisible
// keyframes, as ORB-SLAM3's place recognition matches a place rather than one view of it), a
// RANSAC similarity (geometry/sim3_solver.h; scale fixed to 1 for RGB-D / stereo) in the
// candidate's camera frame, more matches by guided projection, refinement
// (optimize/sim3_optimizer.h), and finally the whole neighbourhood of the candidate projected into
// the current keyframe: a loop is accepted only when enough of those points are found. Callers hold
// the map's update mutex.
#include <optional>
#include <string>
#include <vector>

#include "geometry/camera.h"
#include "geometry/sim3.h"
#include "map/keyframe.h"
#include "mapping/loop_detector.h"
#include "place/bow_matching.h"

namespace edgeslam {

struct LoopVerifierOptions {
  bool fix_scale = false;  // stereo / RGB-D: metric scale is observed
  // The candidate's best covisible keyframes matched with it; 0 matches the candidate alone.
  // A window finds the place when the current view sees it from between two of its keyframes
  // (a new map meeting the first: 5-18 inliers of the 20 needed against the candidate alone).
  std::size_t window_keyframes = 5;
  int min_bow_matches = 20;
  // RANSAC may take a similarity with fewer inliers than the refinement must end with: guided
  // matching adds the matches a rough model finds (ORB-SLAM3 asks 15 of its RANSAC as well).
  int min_ransac_inliers = 15;
  int min_sim3_inliers = 20;
  int min_projected_matches = 40;
  // Monocular: camera centres closer than this fraction of the points' median range leave the
  // scale to the points' ranges (optimize/sim3_optimizer.h). Two clients passing one place meet
  // at 0.000-0.002 (the same frame) and 0.035-0.13 (frames apart), where reprojection agreed with
  // the ranges within 2 %.
  double scale_from_ranges_below_baseline = 0.02;
  float guided_radius = 7.5f;      // px at level 0, for the mutual Sim(3) search
  float projection_radius = 10.f;  // px at level 0, for the neighbourhood projection
  BowMatchOptions bow;
};

struct VerifiedLoop {
  KeyFrame* current = nullptr;
  KeyFrame* loop = nullptr;
  Sim3d S_cl;           // current camera from loop camera (point_current ~= S_cl * point_loop)
  Sim3d S_cw;           // the current keyframe's pose made consistent with the loop side of the map
  int bow_matches = 0;  // over the candidate's window
  int sim3_inliers = 0;
  bool scale_from_ranges = false;  // monocular views at one place: see the options
  int matched_points = 0;
  // One entry per keypoint of the current keyframe: the loop-side point seen there, or nullptr.
  std::vector<MapPoint*> matched;
  // Every good point of the loop keyframe and its covisible keyframes.
  std::vector<MapPoint*> loop_points;
  std::vector<KeyFrame*> loop_keyframes;
};

struct LoopVerification {
  std::optional<VerifiedLoop> loop;
  // Per candidate, why it was rejected (for the log).
  std::vector<std::string> rejections;
};

// Tries the candidates in order; the first that passes every test wins.
LoopVerification verifyLoopCandidates(KeyFrame* current, const std::vector<KeyFrame*>& candidates,
                                      const LoopDetector& detector, const PinholeCamera& camera,
                                      const LoopVerifierOptions& options);

}  // namespace edgeslam
