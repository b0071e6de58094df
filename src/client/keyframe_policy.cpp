#include "client/keyframe_policy.h"

namespace edgeslam {

KeyFrameDecision decideKeyFrame(const KeyFrameParameters& params, const KeyFrameEvidence& e) {
  if (e.frame_tracked < static_cast<std::size_t>(params.min_tracked)) return KeyFrameDecision::kNo;

  const bool enough_features =
      e.reference_features == 0 || static_cast<double>(e.frame_features) >=
                                       params.alpha * static_cast<double>(e.reference_features);
  if (!enough_features) return KeyFrameDecision::kNo;

  const double tracked_ratio =
      e.reference_tracked == 0
          ? 0.0
          : static_cast<double>(e.frame_tracked) / static_cast<double>(e.reference_tracked);
  const bool starving = tracked_ratio < params.starving_ratio;
  if (starving && e.mapper_accepts_urgent) return KeyFrameDecision::kYesStarving;

  // An overdue map update forces a keyframe only while the mapper can still take one: behind a
  // slow link the update is overdue because the edge is behind, and forcing one per frame then
  // flooded the upload queue (lte-congested: ~1 overflow per frame).
  const bool update_overdue =
      !e.map_updates_paused && e.frames_since_map_update >= static_cast<std::size_t>(params.fmax);
  if ((update_overdue || e.frames_since_keyframe >= static_cast<std::size_t>(params.fmax)) &&
      e.mapper_accepts_urgent) {
    return KeyFrameDecision::kYesForced;
  }
  if (params.segmentation_refresh > 0 &&
      e.frames_since_keyframe >= static_cast<std::size_t>(params.segmentation_refresh) &&
      e.mapper_accepts) {
    return KeyFrameDecision::kYesForSegmentation;
  }
  // While paused, the gap alone: "fewer than fmin keyframes in the map" (fmin is 40 on a slow
  // link) then let every frame whose view changed become one, 23 keyframes in the 190 frames of
  // an outage, which the edge took seconds to answer once back.
  const bool rule1 =
      e.frames_since_keyframe > static_cast<std::size_t>(params.fmin) ||
      (!e.map_updates_paused && e.keyframes_in_map < static_cast<std::size_t>(params.fmin));
  // The undisturbed case keeps its ratio exactly as before (a deterministic run stays the same).
  const bool rule4 =
      e.map_updates_paused && e.reference_points > 0
          ? static_cast<double>(e.frame_tracked) / static_cast<double>(e.reference_points) <
                params.beta
          : tracked_ratio < params.beta;
  if (rule1 && rule4 && e.mapper_accepts) return KeyFrameDecision::kYes;
  return KeyFrameDecision::kNo;
}

void KeyFrameDecisionCounts::add(KeyFrameDecision d) {
  switch (d) {
    case KeyFrameDecision::kNo:
      return;
    case KeyFrameDecision::kYes:
      ++by_rules;
      return;
    case KeyFrameDecision::kYesForced:
      ++forced;
      return;
    case KeyFrameDecision::kYesStarving:
      ++starving;
      return;
    case KeyFrameDecision::kYesForSegmentation:
      ++for_segmentation;
      return;
  }
}

}  // namespace edgeslam
