#pragma once
// When a tracked frame becomes a keyframe: the paper's four rules (Sec. V) with the parameters of
// Table I (fmin, fmax, alpha, beta), plus a guard against starving tracking.
//
// The paper's rules, as implemented:
//  (1) more than fmin frames since the last keyframe, or fewer than fmin keyframes in the map;
//  (2) fewer than fmax frames since the last local-map optimisation (the edge's or the local
//  mapper's
//      latest update); past fmax a keyframe is forced so the map keeps up with the camera;
//  (3) the frame has at least alpha times the reference keyframe's feature count (a good image);
//  (4) the frame's tracked points are fewer than beta times the reference keyframe's tracked points
//      (the view has changed).
// A frame is a keyframe when (3) holds and either (1) and (4) hold, or (2) is violated and the
// mapper can take an urgent keyframe (else a slow edge would get one keyframe per frame). While
// map updates are paused (the edge unreachable) only the keyframe gap counts for (2): the update
// is overdue because of the outage, and forcing a keyframe per frame spent the whole allowance of
// unanswered keyframes in the outage's first seconds, leaving tracking none for the rest of it.
// Then rule (4) also compares against every point of the reference keyframe, not only those 3
// keyframes see: no mapper adds observations to the points made during the outage, so few of them
// ever counted, the frame (which counts every point it tracks) stayed above beta of the rest, and
// only rule (2) made keyframes: 5 in the 140 frames of a server restart against 11-12 undisturbed.
// And rule (1) is the keyframe gap alone: the outage's keyframes come at the undisturbed pace.
// Guard (why: with fmin = 10-40 frames, fast motion would lose tracking before the next keyframe is
// allowed): when the tracked ratio falls below `starving_ratio`, rule (1) is waived.
// Segmentation refresh (semantic culling on): people who walk into view appear in the movable mask
// only once a keyframe showing them is segmented, so past `segmentation_refresh` frames since the
// last keyframe a good frame becomes one (0 = off). On generated dynamic sequences keyframe gaps of
// 17-26 frames left people unmasked for that long.
#include <cstddef>

namespace edgeslam {

struct KeyFrameParameters {
  int fmin = 20;
  int fmax = 60;
  double alpha = 0.4;
  double beta = 0.9;
  double starving_ratio = 0.35;
  int min_tracked = 15;  // never a keyframe from a frame that barely tracks
  int segmentation_refresh = 0;
};

struct KeyFrameEvidence {
  std::size_t frames_since_keyframe = 0;
  std::size_t frames_since_map_update = 0;
  std::size_t keyframes_in_map = 0;
  std::size_t frame_features = 0;
  std::size_t reference_features = 0;
  std::size_t frame_tracked = 0;      // inlier matches to map points in this frame
  std::size_t reference_tracked = 0;  // points of the reference keyframe seen by >= 2 keyframes
  std::size_t reference_points = 0;   // every point of the reference keyframe (0 = not given)
  bool mapper_accepts = true;         // false while the mapper is too busy to take one
  bool mapper_accepts_urgent = true;  // the same for a keyframe of starving tracking
  bool map_updates_paused = false;    // no update can come for now (the edge is unreachable)
};

enum class KeyFrameDecision { kNo, kYes, kYesForced, kYesStarving, kYesForSegmentation };

KeyFrameDecision decideKeyFrame(const KeyFrameParameters& params, const KeyFrameEvidence& evidence);

inline bool isKeyFrame(KeyFrameDecision d) {
  return d != KeyFrameDecision::kNo;
}

// How many keyframes each rule made (tells a user why a run has the keyframes it has).
struct KeyFrameDecisionCounts {
  std::size_t by_rules = 0;          // rules (1), (3) and (4)
  std::size_t forced = 0;            // rule (2): the map update or the last keyframe overdue
  std::size_t starving = 0;          // tracking starving
  std::size_t for_segmentation = 0;  // segmentation refresh
  void add(KeyFrameDecision d);
  std::size_t total() const { return by_rules + forced + starving + for_segmentation; }
};

}  // namespace edgeslam
