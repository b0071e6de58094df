#include "client/segmentation_refresh.h"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace edgeslam {

void validate(const SegmentationRefreshOptions& options) {
  if (options.min_frames < 0 || options.max_frames < 0) {
    throw std::invalid_argument("segmentation refresh: negative interval");
  }
  if (options.max_frames > 0 && options.min_frames > options.max_frames) {
    throw std::invalid_argument(
        "segmentation refresh: the shortest interval (" + std::to_string(options.min_frames) +
        " frames) exceeds the longest (" + std::to_string(options.max_frames) + ")");
  }
  if (options.duty_factor < 1) {
    throw std::invalid_argument("segmentation refresh: duty factor below 1");
  }
}

int segmentationRefreshFrames(const SegmentationRefreshOptions& options,
                              std::optional<std::size_t> mask_delay_frames) {
  if (options.max_frames <= 0) return 0;
  if (!mask_delay_frames) return options.max_frames;
  // The delay is capped first so that the product stays small.
  const std::size_t wanted =
      std::min(*mask_delay_frames, static_cast<std::size_t>(options.max_frames)) *
      static_cast<std::size_t>(options.duty_factor);
  return std::clamp(static_cast<int>(wanted), std::max(1, options.min_frames), options.max_frames);
}

}  // namespace edgeslam
