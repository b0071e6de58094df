#pragma once
// Why the tracker has no map yet or lost the camera, counted per cause so that a run can say why
// it waited (metrics.json "initialization" and "lost_frames") instead of only that it did.
#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <utility>

#include "geometry/two_view_initializer.h"

namespace edgeslam {

// Causes for which an attempt to build the first map was refused (the tracker waits).
enum class InitRefusal : std::size_t {
  kTooFewFeatures,      // blank, overexposed or textureless frame
  kTooFewMatches,       // the view changed too much since the reference frame
  kNoModel,             // no homography or fundamental matrix fits
  kLowParallax,         // camera still or only rotating
  kTooFewTriangulated,  // too few points with enough parallax (forward motion, far scene)
  kAmbiguousMotion,     // two motions explain the matches equally well
  kPoorReconstruction,  // the model's inliers do not triangulate consistently
  kWeakMap,             // two-view succeeded but the bundle-adjusted map kept too few points
  kTooFewDepthPoints,   // RGB-D: too few keypoints with a valid depth
  kCount
};
const char* toString(InitRefusal refusal);  // snake_case, the metrics.json key
InitRefusal refusalFor(TwoViewFailure failure);

// Causes for which a frame after initialisation was not tracked.
enum class LostCause : std::size_t {
  kTooFewFeatures,  // nothing to track: blank, overexposed or textureless
  kTrackingFailed,  // features, but too few matched the map
  kCount
};
const char* toString(LostCause cause);

struct TrackingDiagnostics {
  std::optional<std::size_t> initialized_at_frame;  // the first map's (resets keep it)
  std::size_t frames_without_map = 0;               // frames seen before a map existed
  std::size_t initializations = 0;                  // maps built (more than 1 after resets)
  std::array<std::size_t, static_cast<std::size_t>(InitRefusal::kCount)> refusals{};
  std::array<std::size_t, static_cast<std::size_t>(LostCause::kCount)> lost{};
  std::string last_refusal;  // the latest refusal's explanation

  void refuse(InitRefusal refusal, std::string why) {
    ++refusals[static_cast<std::size_t>(refusal)];
    last_refusal = std::move(why);
  }
  void lose(LostCause cause) { ++lost[static_cast<std::size_t>(cause)]; }
  std::size_t refused(InitRefusal refusal) const {
    return refusals[static_cast<std::size_t>(refusal)];
  }
  std::size_t lostTo(LostCause cause) const { return lost[static_cast<std::size_t>(cause)]; }
};

}  // namespace edgeslam
