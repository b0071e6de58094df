#include "io/frame_order_guard.h"

#include <cmath>

namespace edgeslam {

const char* toString(FrameOrderRejection rejection) {
  switch (rejection) {
    case FrameOrderRejection::kDuplicateTimestamp:
      return "duplicate_timestamp";
    case FrameOrderRejection::kTimestampBackwards:
      return "timestamp_backwards";
    case FrameOrderRejection::kNotFinite:
      return "timestamp_not_finite";
  }
  return "?";
}

std::optional<FrameOrderRejection> FrameOrderGuard::check(double timestamp) {
  if (!std::isfinite(timestamp)) {
    ++not_finite_;
    return FrameOrderRejection::kNotFinite;
  }
  if (newest_ && timestamp == *newest_) {
    ++duplicates_;
    return FrameOrderRejection::kDuplicateTimestamp;
  }
  if (newest_ && timestamp < *newest_) {
    ++backwards_;
    return FrameOrderRejection::kTimestampBackwards;
  }
  newest_ = timestamp;
  return std::nullopt;
}

}  // namespace edgeslam
