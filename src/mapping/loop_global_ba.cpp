#include "mapping/loop_global_ba.h"

#include <algorithm>
#include <unordered_map>
#include <unordered_set>
#include <vector>

#include "mapping/loop_map_correction.h"
#include "optimize/local_bundle_adjustment.h"
#include "util/timing_stats.h"

namespace edgeslam {

std::vector<KeyFrame*> connectedKeyFrames(const Map& map, const KeyFrame* seed) {
  std::vector<KeyFrame*> part;
  if (seed == nullptr || seed->isBad()) return part;
  KeyFrame* start = map.keyFrame(seed->id());
  if (start == nullptr) return part;
  std::unordered_set<const KeyFrame*> seen{start};
  std::unordered_set<const MapPoint*> points_seen;
  part.push_back(start);
  for (std::size_t next = 0; next < part.size(); ++next) {
    for (MapPoint* p : part[next]->goodPoints()) {
      if (!points_seen.insert(p).second) continue;
      for (const auto& [id, obs] : p->observations()) {
        if (obs.keyframe->isBad() || !seen.insert(obs.keyframe).second) continue;
        part.push_back(obs.keyframe);
      }
    }
  }
  return part;
}

LoopGlobalBundleAdjustmentResult runLoopGlobalBundleAdjustment(
    Map& map, const PinholeCamera& camera, const std::atomic<bool>* cancel, int iterations,
    const GlobalBundleAdjustmentHooks& hooks, const KeyFrame* loop_keyframe,
    std::size_t max_keyframes) {
  LoopGlobalBundleAdjustmentResult result;
  BundleAdjustmentProblem problem;
  std::vector<KeyFrame*> keyframes;
  std::vector<MapPoint*> points;
  std::vector<std::pair<KeyFrame*, MapPoint*>> owners;  // per observation
  {
    MutexLock lock(map.updateMutex());
    keyframes = loop_keyframe != nullptr ? connectedKeyFrames(map, loop_keyframe) : map.keyFrames();
    if (keyframes.size() < 2) return result;
    if (max_keyframes > 0 && keyframes.size() > max_keyframes) {
      result.keyframes = keyframes.size();
      result.too_large = true;
      return result;
    }
    std::sort(keyframes.begin(), keyframes.end(),
              [](const KeyFrame* a, const KeyFrame* b) { return a->id() < b->id(); });
    // The gauge: the map's origin where the part holds it, else the part's oldest keyframe.
    const KeyFrame* fixed = keyframes.front();
    for (const KeyFrame* kf : keyframes) {
      if (kf == map.originKeyFrame()) fixed = kf;
    }
    std::unordered_map<const KeyFrame*, std::size_t> keyframe_index;
    for (KeyFrame* kf : keyframes) {
      keyframe_index.emplace(kf, problem.keyframes.size());
      problem.keyframes.push_back({kf->id(), kf->pose(), kf == fixed});
    }
    std::vector<MapPoint*> candidates;
    if (loop_keyframe != nullptr) {
      std::unordered_set<MapPoint*> unique;
      for (KeyFrame* kf : keyframes) {
        for (MapPoint* p : kf->goodPoints()) {
          if (unique.insert(p).second) candidates.push_back(p);
        }
      }
      std::sort(candidates.begin(), candidates.end(),
                [](const MapPoint* a, const MapPoint* b) { return a->id() < b->id(); });
    } else {
      candidates = map.mapPoints();
    }
    for (MapPoint* p : candidates) {
      if (p->isBad()) continue;
      const std::size_t point_index = points.size();
      bool observed = false;
      for (const auto& [id, obs] : p->observations()) {
        const auto k = keyframe_index.find(obs.keyframe);
        if (k == keyframe_index.end()) continue;
        const FrameFeatures& f = obs.keyframe->features();
        const cv::KeyPoint& kp = f.keypoints[obs.index];
        std::optional<double> right_u;
        if (!f.right_u.empty() && f.right_u[obs.index] >= 0.f) right_u = f.right_u[obs.index];
        problem.observations.push_back({k->second, point_index, Eigen::Vector2d(kp.pt.x, kp.pt.y),
                                        right_u, f.scales.invSigma2(kp.octave)});
        owners.emplace_back(obs.keyframe, p);
        observed = true;
      }
      if (!observed) continue;
      points.push_back(p);
      problem.points.push_back({p->id(), p->position(), false});
    }
    const FrameFeatures& first = keyframes.front()->features();
    problem.camera = CameraProjection::fromCamera(camera, first.bf > 0.f ? first.bf : -1.0);
  }
  result.keyframes = keyframes.size();
  result.points = points.size();
  result.observations = problem.observations.size();
  if (points.empty()) return result;

  BundleAdjustmentOptions options = BundleAdjustmentOptions::global();
  options.first_pass_iterations = iterations;
  options.cancel = cancel;
  Stopwatch timer;
  const BundleAdjustmentResult solved = bundleAdjust(problem, options);
  result.solve_ms = timer.elapsedMs();
  result.iterations = solved.iterations;
  result.rms_before = solved.rms_before;
  result.rms_after = solved.rms_after;
  if (solved.cancelled || (cancel != nullptr && cancel->load())) {
    result.cancelled = true;
    return result;
  }

  if (hooks.before_apply) hooks.before_apply();
  struct AfterApply {
    const std::function<void()>& call;
    ~AfterApply() {
      if (call) call();
    }
  } after_apply{hooks.after_apply};  // declared before the lock: runs once it is released
  MutexLock lock(map.updateMutex());
  // A loop correction cancels this run without waiting for it and may have taken the lock first:
  // the poses solved here would undo it.
  if (cancel != nullptr && cancel->load()) {
    result.cancelled = true;
    return result;
  }
  for (const std::size_t o : solved.outliers) {
    auto [kf, p] = owners[o];
    if (!kf->isBad() && !p->isBad()) {
      map.eraseObservation(p, kf);
      ++result.outliers_removed;
    }
  }
  MapCorrection correction;
  for (std::size_t k = 0; k < keyframes.size(); ++k) {
    KeyFrame* kf = keyframes[k];
    if (kf->isBad()) continue;
    correction.keyframes.emplace(kf, KeyFrameCorrection{Sim3d(kf->pose()), Sim3d(solved.T_cw[k])});
  }
  for (std::size_t i = 0; i < points.size(); ++i) {
    if (!points[i]->isBad()) correction.point_positions.emplace(points[i], solved.points[i]);
  }
  result.keyframes_propagated = applyMapCorrection(map, correction).keyframes_propagated;
  result.applied = true;
  return result;
}

}  // namespace edgeslam
