#include "relocalize/frame_relocalization.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "geometry/pnp.h"
#include "map/map_matching.h"
#include "optimize/map_optimization.h"
#include "util/timing_stats.h"

namespace edgeslam {
namespace {

int matchCandidate(const KeyFrame& candidate, Frame& frame, const KeyFramePlaces* places) {
  std::fill(frame.points.begin(), frame.points.end(), nullptr);
  std::fill(frame.outliers.begin(), frame.outliers.end(), false);
  if (places == nullptr) return matchKeyFrameByDescriptor(candidate, frame, 0.75f);
  int matched = 0;
  for (const cv::DMatch& m : places->match(candidate)) {
    MapPoint* p = candidate.point(static_cast<std::size_t>(m.trainIdx));
    if (p == nullptr || p->isBad()) continue;
    frame.points[static_cast<std::size_t>(m.queryIdx)] = p;
    ++matched;
  }
  return matched;
}

}  // namespace

int discardFrameOutliers(Frame& frame) {
  int inliers = 0;
  for (std::size_t i = 0; i < frame.size(); ++i) {
    if (frame.points[i] == nullptr) continue;
    if (frame.outliers[i]) {
      frame.points[i]->track_in_view = false;
      frame.points[i]->last_frame_seen = frame.index;
      frame.points[i] = nullptr;
      frame.outliers[i] = false;
    } else if (frame.points[i]->observationCount() > 0) {
      ++inliers;
    }
  }
  return inliers;
}

FrameRelocalization relocalizeFrame(Frame& frame, const std::vector<KeyFrame*>& candidates,
                                    const KeyFramePlaces* places, const PinholeCamera& camera,
                                    const FrameRelocalizationOptions& options) {
  const Stopwatch timer;
  FrameRelocalization out;
  for (KeyFrame* kf : candidates) {
    if (timer.elapsedMs() > options.budget_ms) break;
    ++out.candidates_tried;
    if (matchCandidate(*kf, frame, places) < options.min_matches) continue;
    std::vector<Eigen::Vector2d> pixels;
    std::vector<Eigen::Vector3d> points;
    std::vector<std::size_t> index;
    for (std::size_t i = 0; i < frame.size(); ++i) {
      if (frame.points[i] == nullptr) continue;
      const cv::Point2f& pt = frame.features->keypoints[i].pt;
      pixels.emplace_back(pt.x, pt.y);
      points.push_back(frame.points[i]->position());
      index.push_back(i);
    }
    const PnpResult pnp = solvePnpRansac(pixels, points, camera.K());
    if (!pnp.success) continue;
    for (std::size_t k = 0; k < index.size(); ++k) {
      if (!pnp.inliers[k]) frame.points[index[k]] = nullptr;
    }
    frame.T_cw = pnp.camera_from_world;
    optimizeFramePose(frame);
    int inliers = discardFrameOutliers(frame);
    if (inliers < options.min_inliers) {
      std::vector<MapPoint*> found;
      for (MapPoint* p : frame.points) {
        if (p != nullptr) found.push_back(p);
      }
      matchKeyFrameByProjection(frame, *kf, found, 10.f, 100);
      optimizeFramePose(frame);
      inliers = discardFrameOutliers(frame);
    }
    if (inliers >= options.min_inliers) {
      out.keyframe = kf;
      out.inliers = inliers;
      return out;
    }
  }
  spdlog::debug("frame {}: not relocalised ({} candidates, {:.1f} ms)", frame.index,
                out.candidates_tried, timer.elapsedMs());
  std::fill(frame.points.begin(), frame.points.end(), nullptr);
  frame.T_cw.reset();
  return out;
}

}  // namespace edgeslam
