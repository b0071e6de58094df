#include "client/tracking_diagnostics.h"

namespace edgeslam {

const char* toString(InitRefusal refusal) {
  switch (refusal) {
    case InitRefusal::kTooFewFeatures:
      return "too_few_features";
    case InitRefusal::kTooFewMatches:
      return "too_few_matches";
    case InitRefusal::kNoModel:
      return "no_model";
    case InitRefusal::kLowParallax:
      return "low_parallax";
    case InitRefusal::kTooFewTriangulated:
      return "too_few_triangulated";
    case InitRefusal::kAmbiguousMotion:
      return "ambiguous_motion";
    case InitRefusal::kPoorReconstruction:
      return "poor_reconstruction";
    case InitRefusal::kWeakMap:
      return "weak_map";
    case InitRefusal::kTooFewDepthPoints:
      return "too_few_depth_points";
    case InitRefusal::kCount:
      break;
  }
  return "?";
}

InitRefusal refusalFor(TwoViewFailure failure) {
  switch (failure) {
    case TwoViewFailure::kTooFewMatches:
      return InitRefusal::kTooFewMatches;
    case TwoViewFailure::kLowParallax:
      return InitRefusal::kLowParallax;
    case TwoViewFailure::kTooFewTriangulated:
      return InitRefusal::kTooFewTriangulated;
    case TwoViewFailure::kAmbiguousMotion:
      return InitRefusal::kAmbiguousMotion;
    case TwoViewFailure::kPoorReconstruction:
      return InitRefusal::kPoorReconstruction;
    case TwoViewFailure::kNone:
    case TwoViewFailure::kNoModel:
      break;
  }
  return InitRefusal::kNoModel;
}

const char* toString(LostCause cause) {
  switch (cause) {
    case LostCause::kTooFewFeatures:
      return "too_few_features";
    case LostCause::kTrackingFailed:
      return "tracking_failed";
    case LostCause::kCount:
      break;
  }
  return "?";
}

}  // namespace edgeslam
