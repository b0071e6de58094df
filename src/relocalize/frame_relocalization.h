#pragma once
// A lost frame's pose from keyframes that look like it: each candidate, best first, is matched to
// the frame (word by word through the places' direct index, else by descriptor), the matches go
// through PnP RANSAC, and the pose is refined against the candidate's points, widened by a
// projection search when too few survive. The client's tracker and the edge's localisation
// sessions both call it.
#include <vector>

#include "geometry/camera.h"
#include "map/frame.h"
#include "map/keyframe.h"
#include "relocalize/keyframe_places.h"

namespace edgeslam {

struct FrameRelocalizationOptions {
  // Time the search may take: candidates past it are not tried (the next frame tries again).
  double budget_ms = 25.0;
  int min_matches = 15;  // candidate-to-frame matches worth a PnP
  int min_inliers = 50;  // inliers after refinement for the pose to count
};

struct FrameRelocalization {
  KeyFrame* keyframe = nullptr;  // the candidate that gave the pose; nullptr: not relocalised
  int inliers = 0;
  std::size_t candidates_tried = 0;
};

// On success, frame.T_cw is set and frame.points holds the inlier matches; otherwise both are
// cleared. `places` (may be nullptr) must have been asked for this frame last (similar()). The
// caller holds the map's update mutex.
FrameRelocalization relocalizeFrame(Frame& frame, const std::vector<KeyFrame*>& candidates,
                                    const KeyFramePlaces* places, const PinholeCamera& camera,
                                    const FrameRelocalizationOptions& options = {});

// Drops the matches pose optimisation flagged as outliers (their points are told they were not
// found in view) and returns how many of the rest are points still observed by a keyframe.
int discardFrameOutliers(Frame& frame);

}  // namespace edgeslam
