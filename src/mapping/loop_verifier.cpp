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

// One Sim3Match per entry of `matched` whose loop point the loop keyframe observes.
MatchSet toSim3Matches(const KeyFrame& current, const KeyFrame& loop,
                       const std::vector<MapPoint*>& matched) {
  MatchSet out;
  for (std::size_t i = 0; i < matched.size(); ++i) {
    MapPoint* loop_point = matched[i];
    MapPoint* own = current.point(i);
    if (loop_point == nullptr || own == nullptr || own->isBad() || loop_point->isBad()) continue;
    const auto obs = loop_point->observations().find(loop.id());
    if (obs == loop_point->observations().end()) continue;
    const std::size_t j = obs->second.index;
    out.matches.push_back({current.pose() * own->position(), loop.pose() * loop_point->position(),
                           pixelOf(current, i), pixelOf(loop, j), sigmaOf(current, i),
                           sigmaOf(loop, j)});
    out.current_index.push_back(i);
    out.loop_point.push_back(loop_point);
  }
  return out;
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
    const FrameFeatures& fl = candidate->features();
    const auto bow_matches = matchByBow(current_features, fc.keypoints, fc.descriptors,
                                        withPointsOnly(candidate_bow->features, *candidate),
                                        fl.keypoints, fl.descriptors, options.bow);
    std::vector<MapPoint*> matched(current->size(), nullptr);
    int bow_count = 0;
    for (const cv::DMatch& m : bow_matches) {
      MapPoint* p = candidate->point(static_cast<std::size_t>(m.trainIdx));
      if (p == nullptr || p->isBad()) continue;
      matched[static_cast<std::size_t>(m.queryIdx)] = p;
      ++bow_count;
    }
    if (bow_count < options.min_bow_matches) {
      reject(fmt::format("{} BoW matches", bow_count));
      continue;
    }

    MatchSet set = toSim3Matches(*current, *candidate, matched);
    Sim3SolverOptions ransac;
    ransac.fix_scale = options.fix_scale;
    ransac.min_inliers = options.min_sim3_inliers;
    const Sim3Result estimate = solveSim3Ransac(set.matches, K, K, ransac);
    if (!estimate.success) {
      reject(fmt::format("{} BoW matches, RANSAC failed ({})", bow_count, estimate.reason));
      continue;
    }
    keepInliers(
        set, [&](std::size_t k) { return estimate.inliers[k] != 0; }, matched);

    searchBySim3(*current, *candidate, estimate.cam1_from_cam2, camera, matched,
                 options.guided_radius, kGuidedMaxDistance);
    set = toSim3Matches(*current, *candidate, matched);
    Sim3RefinementOptions refine;
    refine.fix_scale = options.fix_scale;
    refine.min_inliers = options.min_sim3_inliers;
    const Sim3RefinementResult refined =
        refineSim3(estimate.cam1_from_cam2, set.matches, projection, projection, refine);
    if (!refined.success || refined.inliers < options.min_sim3_inliers) {
      reject(fmt::format("{} BoW matches, {} RANSAC inliers, {} after refinement", bow_count,
                         estimate.num_inliers, refined.inliers));
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
    loop.loop_keyframes.push_back(candidate);
    for (const auto& [kf, weight] : candidate->connections()) {
      if (!kf->isBad()) loop.loop_keyframes.push_back(kf);
    }
    std::unordered_set<const MapPoint*> seen;
    for (KeyFrame* kf : loop.loop_keyframes) {
      for (MapPoint* p : kf->points()) {
        if (p != nullptr && !p->isBad() && seen.insert(p).second) loop.loop_points.push_back(p);
      }
    }
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
