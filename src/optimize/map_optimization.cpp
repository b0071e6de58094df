#include "optimize/map_optimization.h"

#include <fmt/format.h>

#include <unordered_map>

#include "util/timing_stats.h"

namespace edgeslam {
namespace {

CameraProjection projectionFor(const PinholeCamera& camera, const FrameFeatures& features) {
  return CameraProjection::fromCamera(camera, features.bf > 0.f ? features.bf : -1.0);
}

std::optional<double> rightU(const FrameFeatures& features, std::size_t i) {
  if (features.right_u.empty() || features.right_u[i] < 0.f) return std::nullopt;
  return features.right_u[i];
}

// Keyframes linked by the points they share form parts; a part with no fixed keyframe (another
// client's part of a shared map before a loop joins it to the origin's, or a window away from
// every fixed keyframe) would float: its oldest keyframe holds it.
void fixGaugeOfFloatingParts(BundleAdjustmentProblem& problem) {
  const std::size_t n = problem.keyframes.size();
  std::vector<std::size_t> root(n);
  for (std::size_t k = 0; k < n; ++k) root[k] = k;
  const auto find = [&](std::size_t k) {
    while (root[k] != k) k = root[k] = root[root[k]];
    return k;
  };
  std::vector<std::size_t> first_observer(problem.points.size(), n);
  for (const auto& obs : problem.observations) {
    std::size_t& first = first_observer[obs.point];
    if (first == n) {
      first = obs.keyframe;
    } else {
      root[find(obs.keyframe)] = find(first);
    }
  }
  std::vector<bool> held(n, false);
  for (std::size_t k = 0; k < n; ++k) {
    if (problem.keyframes[k].fixed) held[find(k)] = true;
  }
  std::vector<std::size_t> oldest(n, n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t part = find(k);
    if (held[part]) continue;
    if (oldest[part] == n || problem.keyframes[k].id < problem.keyframes[oldest[part]].id) {
      oldest[part] = k;
    }
  }
  for (std::size_t part = 0; part < n; ++part) {
    if (oldest[part] != n) problem.keyframes[oldest[part]].fixed = true;
  }
}

// Builds the problem for the given free keyframes; returns false when there is nothing to optimise.
struct ProblemBuild {
  BundleAdjustmentProblem problem;
  std::vector<KeyFrame*> keyframes;
  std::vector<MapPoint*> points;
  std::vector<std::pair<KeyFrame*, MapPoint*>> observation_owners;
};

ProblemBuild buildProblem(const std::vector<KeyFrame*>& free_keyframes, KeyFrame* gauge,
                          const PinholeCamera& camera) {
  ProblemBuild build;
  std::unordered_map<KeyFrame*, std::size_t> kf_index;
  std::unordered_map<MapPoint*, std::size_t> point_index;
  auto addKeyFrame = [&](KeyFrame* kf, bool fixed) {
    const auto [it, inserted] = kf_index.try_emplace(kf, build.keyframes.size());
    if (inserted) {
      build.keyframes.push_back(kf);
      build.problem.keyframes.push_back({kf->id(), kf->pose(), fixed || kf == gauge});
    }
    return it->second;
  };
  for (KeyFrame* kf : free_keyframes) addKeyFrame(kf, false);
  for (KeyFrame* kf : free_keyframes) {
    for (MapPoint* p : kf->points()) {
      if (p == nullptr || p->isBad() || point_index.contains(p)) continue;
      point_index.emplace(p, build.points.size());
      build.points.push_back(p);
      build.problem.points.push_back({p->id(), p->position(), false});
    }
  }
  for (std::size_t pi = 0; pi < build.points.size(); ++pi) {
    MapPoint* p = build.points[pi];
    for (const auto& [id, obs] : p->observations()) {
      KeyFrame* kf = obs.keyframe;
      if (kf->isBad()) continue;
      const std::size_t ki = addKeyFrame(kf, true);
      const FrameFeatures& f = kf->features();
      const cv::KeyPoint& kp = f.keypoints[obs.index];
      build.problem.observations.push_back({ki, pi, Eigen::Vector2d(kp.pt.x, kp.pt.y),
                                            rightU(f, obs.index), f.scales.invSigma2(kp.octave)});
      build.observation_owners.emplace_back(kf, p);
    }
  }
  fixGaugeOfFloatingParts(build.problem);
  if (!build.keyframes.empty()) {
    build.problem.camera = projectionFor(camera, build.keyframes.front()->features());
  }
  return build;
}

// The solved poses of the free keyframes and the solved points into the map.
void writeBack(Map& map, const ProblemBuild& build, const std::vector<SE3d>& T_cw,
               const std::vector<Eigen::Vector3d>& points) REQUIRES(map.updateMutex()) {
  for (std::size_t k = 0; k < build.keyframes.size(); ++k) {
    if (build.problem.keyframes[k].fixed || build.keyframes[k]->isBad()) continue;
    map.setKeyFramePose(build.keyframes[k], T_cw[k]);
  }
  for (std::size_t i = 0; i < build.points.size(); ++i) {
    MapPoint* p = build.points[i];
    if (p->isBad()) continue;
    map.setPointPosition(p, points[i]);
    map.refreshPoint(p);
  }
}

LocalBundleAdjustmentStats solveAndApply(Map& map, ProblemBuild build,
                                         const BundleAdjustmentOptions& options) {
  LocalBundleAdjustmentStats stats;
  for (const auto& kf : build.problem.keyframes)
    (kf.fixed ? stats.fixed_keyframes : stats.keyframes)++;
  stats.points = build.points.size();
  stats.observations = build.problem.observations.size();
  if (stats.keyframes == 0 || stats.points == 0) return stats;

  Stopwatch timer;
  const BundleAdjustmentResult result = bundleAdjust(build.problem, options);
  stats.solve_ms = timer.elapsedMs();
  stats.cancelled = result.cancelled;
  stats.rms_before = result.rms_before;
  stats.rms_after = result.rms_after;
  if (result.cancelled && result.iterations == 0) return stats;

  MutexLock lock(map.updateMutex());
  for (std::size_t o : result.outliers) {
    auto [kf, p] = build.observation_owners[o];
    if (!kf->isBad() && !p->isBad()) {
      map.eraseObservation(p, kf);
      ++stats.outliers_removed;
    }
  }
  writeBack(map, build, result.T_cw, result.points);
  return stats;
}

}  // namespace

int optimizeFramePose(Frame& frame, const PoseOptimizerOptions& options) {
  const FrameFeatures& f = *frame.features;
  std::vector<PoseObservation> observations;
  std::vector<std::size_t> keypoint_of;
  observations.reserve(frame.size());
  for (std::size_t i = 0; i < frame.size(); ++i) {
    MapPoint* p = frame.points[i];
    if (p == nullptr) continue;
    const cv::KeyPoint& kp = f.keypoints[i];
    observations.push_back({p->position(), Eigen::Vector2d(kp.pt.x, kp.pt.y), rightU(f, i),
                            f.scales.invSigma2(kp.octave)});
    keypoint_of.push_back(i);
  }
  if (observations.size() < 3) return 0;
  const PoseOptimizerResult result =
      optimizePose(*frame.T_cw, observations, projectionFor(*frame.camera, f), options);
  frame.T_cw = result.T_cw;
  for (std::size_t k = 0; k < keypoint_of.size(); ++k) {
    frame.outliers[keypoint_of[k]] = result.outliers[k];
  }
  return result.inliers;
}

LocalBundleAdjustmentStats localBundleAdjustment(Map& map, KeyFrame* keyframe,
                                                 const PinholeCamera& camera,
                                                 const std::atomic<bool>* cancel,
                                                 BundleAdjustmentOptions options) {
  ProblemBuild build;
  {
    MutexLock lock(map.updateMutex());
    if (keyframe->isBad()) return {};
    std::vector<KeyFrame*> window = keyframe->bestCovisibles(static_cast<std::size_t>(-1));
    window.insert(window.begin(), keyframe);
    build = buildProblem(window, map.originKeyFrame(), camera);
  }
  options.cancel = cancel;
  return solveAndApply(map, std::move(build), options);
}

LocalBundleAdjustmentStats globalBundleAdjustment(Map& map, const PinholeCamera& camera,
                                                  const std::atomic<bool>* cancel, int iterations) {
  ProblemBuild build;
  {
    MutexLock lock(map.updateMutex());
    build = buildProblem(map.keyFrames(), map.originKeyFrame(), camera);
  }
  BundleAdjustmentOptions options = BundleAdjustmentOptions::global();
  options.first_pass_iterations = iterations;
  options.cancel = cancel;
  return solveAndApply(map, std::move(build), options);
}

MapIntrinsicsRefinement refineMapIntrinsics(Map& map, const PinholeCamera& camera,
                                            const IntrinsicsRefinementOptions& options) {
  ProblemBuild build;
  {
    MutexLock lock(map.updateMutex());
    build = buildProblem(map.keyFrames(), map.originKeyFrame(), camera);
  }
  MapIntrinsicsRefinement out;
  out.keyframes = build.keyframes.size();
  out.points = build.points.size();
  if (build.problem.observations.empty()) {
    out.result.reason = "the map has no observations";
    out.result.intrinsics = out.result.estimate = camera.intrinsics();
    return out;
  }
  Stopwatch timer;
  out.result = refineIntrinsics(build.problem, camera, options);
  out.solve_ms = timer.elapsedMs();
  if (!out.result.adopted) return out;
  MutexLock lock(map.updateMutex());
  writeBack(map, build, out.result.T_cw, out.result.points);
  return out;
}

std::string describe(const MapIntrinsicsRefinement& refinement) {
  const IntrinsicsRefinementResult& r = refinement.result;
  if (!r.adopted) {
    return fmt::format("kept: {} ({:.0f} ms over {} keyframes)", r.reason, refinement.solve_ms,
                       refinement.keyframes);
  }
  const CameraIntrinsics& in = r.intrinsics;
  return fmt::format(
      "refined fx {:.2f} fy {:.2f} k1 {:.4f} k2 {:.4f}, reprojection RMS {:.3f} -> {:.3f} px "
      "({:.0f} ms over {} keyframes)",
      in.fx, in.fy, in.distortion.k1, in.distortion.k2, r.rms_before, r.rms_after,
      refinement.solve_ms, refinement.keyframes);
}

}  // namespace edgeslam
