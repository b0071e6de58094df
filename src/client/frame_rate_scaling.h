#pragma once
// Frame counts of the keyframe rules (paper Table I, whose values the defaults take) are counts
// of a 30 fps camera: a slower camera covers the same time in fewer frames, so the counts shrink
// with its rate (a faster one keeps them).
#include <algorithm>
#include <cmath>

#include "client/keyframe_policy.h"

namespace edgeslam {

// This camera's frames per frame of a 30 fps camera: its rate over 30 fps, at most 1; 1 when the
// rate is unknown (0).
inline double rateAgainst30Fps(double camera_fps) {
  return camera_fps > 0.0 ? std::min(1.0, camera_fps / 30.0) : 1.0;
}

// `frames` of a 30 fps camera in this camera's frames: 0 (off) stays 0, anything else is at
// least 1.
inline int framesAtCameraRate(int frames, double camera_fps) {
  if (frames <= 0) return 0;
  return std::max(1, static_cast<int>(std::lround(frames * rateAgainst30Fps(camera_fps))));
}

// Keyframe rules 1 and 2 (fmin, fmax), given in frames of a 30 fps camera. Below 15 fps rule 1 is
// dropped altogether: consecutive frames are then already far apart (KITTI at 10 fps drives ~1 m
// per frame) and a minimum gap starves monocular tracking (KITTI 07: ATE 39 cm with fmin 3, 22-26
// cm with fmin 0; 7-Scenes at 30 fps is best with fmin 10).
inline void setKeyFrameGaps(KeyFrameParameters& keyframes, int fmin, int fmax, double camera_fps) {
  const double rate = rateAgainst30Fps(camera_fps);
  keyframes.fmin = rate < 0.5 ? 0 : static_cast<int>(std::lround(fmin * rate));
  keyframes.fmax = std::max(1, static_cast<int>(std::lround(fmax * rate)));
}

}  // namespace edgeslam
