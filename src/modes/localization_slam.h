#pragma once
// Localisation in a map made earlier (`run --mode local --localize-only --map NAME`): a stored
// session's map is loaded as the client's map, the first frames relocalise in it (bag-of-words
// candidates, PnP RANSAC, pose refinement) and tracking follows it. No keyframe is made and
// nothing is mapped or written back: poses are in the stored map's frame.
#include "modes/slam_system.h"
#include "store/map_store.h"

namespace edgeslam {

class LocalizationSlam : public TrackingSlam {
 public:
  // Throws std::invalid_argument when the session cannot serve this camera (another sensor or
  // image size) or there is no vocabulary to relocalise with.
  LocalizationSlam(const PinholeCamera& camera, SlamOptions options, const StoredSession& session);

  void finish() override {}
  const char* modeName() const override { return "local"; }
  SlamCounters counters() const override;
  std::size_t storedKeyFrames() const { return stored_keyframes_; }

 private:
  std::size_t stored_keyframes_ = 0;
};

}  // namespace edgeslam
