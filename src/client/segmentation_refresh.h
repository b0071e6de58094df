#pragma once
// How often a frame is made a keyframe so that it gets segmented (semantic culling on): people who
// walk into view are masked only once a keyframe showing them is segmented, so the sooner the
// better, but each refresh costs the edge a segmentation. The interval follows how late the masks
// come back: every `duty_factor` times their delay (in frames), so that segmentation keeps the
// edge busy at most 1/duty_factor of the time, within [min_frames, max_frames].
//
// On generated dynamic sequences (seed 11, edge mode) with masks back 1 frame after their
// keyframe, every 6 frames instead of 12 raised the mask IoU from 0.63-0.76 to 0.75-0.81; on a
// host where they came back 5-7 frames late, every 8 frames made it worse (0.39-0.46 against
// 0.48), the edge's core being taken by segmentation.
#include <cstddef>
#include <optional>

namespace edgeslam {

struct SegmentationRefreshOptions {
  int min_frames = 6;
  int max_frames = 12;  // also the interval before any mask came back; 0 = no refresh keyframes
  int duty_factor = 4;
};

// Throws std::invalid_argument for a negative bound, min_frames > max_frames (when max > 0) or a
// duty factor below 1.
void validate(const SegmentationRefreshOptions& options);

// The interval in frames (0 = no refresh keyframes) for masks typically `mask_delay_frames` late
// (nullopt: none back yet).
int segmentationRefreshFrames(const SegmentationRefreshOptions& options,
                              std::optional<std::size_t> mask_delay_frames);

}  // namespace edgeslam
