#pragma once
// Monocular map initialisation: keeps a reference frame, matches later frames to it and, once the
// two views have enough parallax, builds the first two keyframes and their points (unit median
// depth).
#include <memory>
#include <optional>

#include "client/tracking_diagnostics.h"
#include "geometry/camera.h"
#include "geometry/two_view_initializer.h"
#include "map/frame.h"
#include "map/map.h"

namespace edgeslam {

struct MonocularInitializerOptions {
  int min_features = 100;  // frames with fewer are not used
  int min_matches = 100;   // fewer matches to the reference: start again from the current frame
  float search_radius = 100.f;
  int min_map_points = 100;            // after the initial BA; fewer means a bad start
  std::size_t max_reference_age = 30;  // frames; an old reference is replaced
  // A first map from a short baseline with few points is fragile: ask for 150 well-triangulated
  // points (the two-view default is 50).
  TwoViewOptions two_view = [] {
    TwoViewOptions o;
    o.min_triangulated = 150;
    return o;
  }();
};

class MonocularInitializer {
 public:
  MonocularInitializer(const PinholeCamera& camera, MonocularInitializerOptions options = {});

  // Tries to initialise from `frame`; on success the map holds two more keyframes and `frame` has
  // its pose and point matches set. Returns the second keyframe (the current frame's) or nullptr.
  // The map may hold an older map already (a new one started after tracking was lost for good):
  // it is left as it is, and the new keyframes share nothing with it.
  KeyFrame* tryInitialize(Frame& frame, Map& map) EXCLUDES(map.updateMutex());
  // The first of the two keyframes the last successful tryInitialize made (the reference frame's).
  KeyFrame* referenceKeyFrame() const { return reference_keyframe_; }
  const std::string& lastFailure() const { return last_failure_; }
  // Why the last call built no map; nullopt when it only waited (a new reference frame).
  std::optional<InitRefusal> lastRefusal() const { return last_refusal_; }
  int attempts() const { return attempts_; }

 private:
  void resetReference(const Frame& frame);

  const PinholeCamera& camera_;
  MonocularInitializerOptions options_;
  std::optional<Frame> reference_;
  KeyFrame* reference_keyframe_ = nullptr;
  void refuse(InitRefusal refusal, std::string why);

  std::string last_failure_;
  std::optional<InitRefusal> last_refusal_;
  int attempts_ = 0;
};

}  // namespace edgeslam
