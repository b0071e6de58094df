#include "mapping/loop_verifier.h"

#include <cmath>
#include <unordered_set>

#include "fmt/format.h"
#include "geometry/sim3_solver.h"
#include "mapping/loop_matching.h"
#include "optimize/sim3_optimizer.h"

namespace edgeslam {
namespace {

constexpr int kGuidedMaxDistance = 100;
constexpr int kProjectionMaxDistance = 50;

// The direct index limited to the features that observe a good map point.
FeatureVector withPointsOnly(const FeatureVector& features, const KeyFrame& keyframe) {
  std::vector<std::pair<NodeId, int>> pairs;
  pairs.reserve(features.featureCount());
  for (std::size_t n = 0; n < features.size(); ++n) {
    for (const int i : features.features(n)) {
      const MapPoint* p = keyframe.point(static_cast<std::size_t>(i));
      if (p != nullptr && !p->isBad()) pairs.emplace_back(features.node(n), i);
    }
  }
  return FeatureVector::fromPairs(std::move(pairs));
}

Eigen::Vector2d pixelOf(const KeyFrame& kf, std::size_t i) {
  const cv::KeyPoint& kp = kf.features().keypoints[i];
  return {kp.pt.x, kp.pt.y};
}

double sigmaOf(const KeyFrame& kf, std::size_t i) {
  return std::sqrt(kf.features().scales.sigma2(kf.features().keypoints[i].octave));
}

struct MatchSet {
  std::vector<Sim3Match> matches;
  std::vector<std::size_t> current_index;  // keypoint in the current keyframe, per match
  std::vector<MapPoint*> loop_point;       // the loop keyframe's point, per match
};

// Keeps in `matched` only the matches flagged as inliers.
template <typename Flags>
void keepInliers(const MatchSet& set, const Flags& is_inlier, std::vector<MapPoint*>& matched) {
  std::fill(matched.begin(), matched.end(), nullptr);
  for (std::size_t k = 0; k < set.matches.size(); ++k) {
    if (is_inlier(k)) matched[set.current_index[k]] = set.loop_point[k];
  }
}

// One Sim3Match per entry of `matched`, in the loop keyframe's camera frame. A loop point the loop
// keyframe does not observe (one of its window's) is given its projection there as the
// observation, at the current keyframe's noise; one behind the loop camera is left out.
MatchSet toSim3Matches(const KeyFrame& current, const KeyFrame& loop, const PinholeCamera& camera,
                       const std::vector<MapPoint*>& matched) {
  MatchSet out;
  for (std::size_t i = 0; i < matched.size(); ++i) {
    MapPoint* loop_point = matched[i];
    MapPoint* own = current.point(i);
    if (loop_point == nullptr || own == nullptr || own->isBad() || loop_point->isBad()) continue;
    const Eigen::Vector3d in_loop = loop.pose() * loop_point->position();
    Eigen::Vector2d pixel2;
    double sigma2 = 0.0;
    const auto obs = loop_point->observations().find(loop.id());
    if (obs != loop_point->observations().end()) {
      pixel2 = pixelOf(loop, obs->second.index);
      sigma2 = sigmaOf(loop, obs->second.index);
    } else {
      if (!(in_loop.z() > 0.0)) continue;
      pixel2 = {camera.fx() * in_loop.x() / in_loop.z() + camera.cx(),
                camera.fy() * in_loop.y() / in_loop.z() + camera.cy()};
      sigma2 = sigmaOf(current, i);
    }
    out.matches.push_back({current.pose() * own->position(), in_loop, pixelOf(current, i), pixel2,
                           sigmaOf(current, i), sigma2});
    out.current_index.push_back(i);
    out.loop_point.push_back(loop_point);
  }
  return out;
}

// The candidate and its best covisible keyframes, those good and not connected to the current
// keyframe (their points would match the current keyframe's own and pull towards no correction).
std::vector<KeyFrame*> windowOf(KeyFrame* candidate, const KeyFrame& current,
                                std::size_t covisibles) {
  std::vector<KeyFrame*> window{candidate};
  if (covisibles == 0) return window;
  for (KeyFrame* kf : candidate->bestCovisibles(covisibles)) {
    if (kf == nullptr || kf->isBad() || kf == &current || current.connections().contains(kf)) {
      continue;
    }
    window.push_back(kf);
  }
  return window;
}

// Bag-of-words matches of the current keyframe's points against each keyframe of the window in
// turn; a current keypoint keeps its first match and a window point is matched once (a point of
// the candidate's covisibles that the current keyframe observes is not a match). Returns the
// number of matches written into `matched`.
int matchWindowByBow(const KeyFrame& current, const FeatureVector& current_features,
                     const FrameFeatures& fc, const std::vector<KeyFrame*>& window,
                     const LoopDetector& detector, const BowMatchOptions& options,
                     std::vector<MapPoint*>& matched) {
  std::unordered_set<const MapPoint*> used;
  int count = 0;
  for (KeyFrame* kf : window) {
    const KeyFrameBow* bow = detector.bowOf(kf->id());
    if (bow == nullptr) continue;
    const FrameFeatures& fk = kf->features();
    const auto matches =
        matchByBow(current_features, fc.keypoints, fc.descriptors,
                   withPointsOnly(bow->features, *kf), fk.keypoints, fk.descriptors, options);
    for (const cv::DMatch& m : matches) {
      MapPoint* p = kf->point(static_cast<std::size_t>(m.trainIdx));
      if (p == nullptr || p->isBad()) continue;
      if (kf != window.front() && p->observations().contains(current.id())) continue;
      MapPoint*& slot = matched[static_cast<std::size_t>(m.queryIdx)];
      if (slot != nullptr || !used.insert(p).second) continue;
      slot = p;
      ++count;
    }
  }
  return count;
}

// Every good point of the given keyframes, each once, but those `except` observes.
std::vector<MapPoint*> pointsOf(const std::vector<KeyFrame*>& keyframes,
                                const KeyFrame* except = nullptr) {
  std::vector<MapPoint*> points;
  std::unordered_set<const MapPoint*> seen;
  for (KeyFrame* kf : keyframes) {
    for (MapPoint* p : kf->points()) {
      if (p == nullptr || p->isBad() || !seen.insert(p).second) continue;
      if (except != nullptr && p->observations().contains(except->id())) continue;
      points.push_back(p);
    }
  }
  return points;
}

}  // namespace

LoopVerification verifyLoopCandidates(KeyFrame* current, const std::vector<KeyFrame*>& candidates,
                                      const LoopDetector& detector, const PinholeCamera& camera,
                                      const LoopVerifierOptions& options) {
  LoopVerification out;
  const KeyFrameBow* current_bow = detector.bowOf(current->id());
  if (current_bow == nullptr || current->isBad()) {
    out.rejections.push_back("current keyframe has no bag of words");
    return out;
  }
  const FeatureVector current_features = withPointsOnly(current_bow->features, *current);
  const FrameFeatures& fc = current->features();
  const CameraProjection projection = CameraProjection::fromCamera(camera, 0.0);
  const Eigen::Matrix3d K = camera.K();

  for (KeyFrame* candidate : candidates) {
    const auto reject = [&](const std::string& why) {
      out.rejections.push_back(fmt::format("keyframe {}: {}", candidate->id(), why));
    };
    const KeyFrameBow* candidate_bow = detector.bowOf(candidate->id());
    if (candidate->isBad() || candidate_bow == nullptr) {
      reject("gone");
      continue;
    }
    const std::vector<KeyFrame*> window = windowOf(candidate, *current, options.window_keyframes);
    std::vector<MapPoint*> matched(current->size(), nullptr);
    const int bow_count =
        matchWindowByBow(*current, current_features, fc, window, detector, options.bow, matched);
    if (bow_count < options.min_bow_matches) {
      reject(fmt::format("{} BoW matches over {} keyframes", bow_count, window.size()));
      continue;
    }

    MatchSet set = toSim3Matches(*current, *candidate, camera, matched);
    Sim3SolverOptions ransac;
    ransac.fix_scale = options.fix_scale;
    ransac.min_inliers = options.min_ransac_inliers;
    const Sim3Result estimate = solveSim3Ransac(set.matches, K, K, ransac);
    if (!estimate.success) {
      reject(fmt::format("{} BoW matches, RANSAC failed ({})", bow_count, estimate.reason));
      continue;
    }
    keepInliers(
        set, [&](std::size_t k) { return estimate.inliers[k] != 0; }, matched);

    searchBySim3(*current, *candidate, estimate.cam1_from_cam2, camera, matched,
                 options.guided_radius, kGuidedMaxDistance);
    if (window.size() > 1) {
      searchByProjectionSim3(*current, estimate.cam1_from_cam2 * Sim3d(candidate->pose()), camera,
                             pointsOf(window, current), matched, options.guided_radius,
                             kProjectionMaxDistance);
    }
    set = toSim3Matches(*current, *candidate, camera, matched);
    Sim3RefinementOptions refine;
    refine.fix_scale = options.fix_scale;
    refine.min_inliers = options.min_sim3_inliers;
    if (!options.fix_scale) {
      refine.scale_from_ranges_below_baseline = options.scale_from_ranges_below_baseline;
    }
    const Sim3RefinementResult refined =
        refineSim3(estimate.cam1_from_cam2, set.matches, projection, projection, refine);
    if (!refined.success || refined.inliers < options.min_sim3_inliers) {
      reject(fmt::format("{} BoW matches, {} RANSAC inliers, {} after refinement{}", bow_count,
                         estimate.num_inliers, refined.inliers,
                         refined.scale_from_ranges ? " (scale held at the points' ranges)" : ""));
      continue;
    }
    keepInliers(
        set, [&](std::size_t k) { return !refined.outliers[k]; }, matched);

    VerifiedLoop loop;
    loop.current = current;
    loop.loop = candidate;
    loop.S_cl = refined.S_12;
    loop.S_cw = refined.S_12 * Sim3d(candidate->pose());
    loop.bow_matches = bow_count;
    loop.sim3_inliers = refined.inliers;
    loop.scale_from_ranges = refined.scale_from_ranges;
    loop.loop_keyframes.push_back(candidate);
    for (const auto& [kf, weight] : candidate->connections()) {
      if (!kf->isBad()) loop.loop_keyframes.push_back(kf);
    }
    loop.loop_points = pointsOf(loop.loop_keyframes);
    loop.matched = std::move(matched);
    searchByProjectionSim3(*current, loop.S_cw, camera, loop.loop_points, loop.matched,
                           options.projection_radius, kProjectionMaxDistance);
    loop.matched_points = static_cast<int>(
        loop.matched.size() - std::count(loop.matched.begin(), loop.matched.end(), nullptr));
    if (loop.matched_points < options.min_projected_matches) {
      reject(fmt::format("{} Sim3 inliers but only {} points of the loop neighbourhood found",
                         refined.inliers, loop.matched_points));
      continue;
    }
    out.loop = std::move(loop);
    return out;
  }
  return out;
}

}  // namespace edgeslam
