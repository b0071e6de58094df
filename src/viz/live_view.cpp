#include "viz/live_view.h"

#include <algorithm>
#include <utility>

namespace edgeslam::viz {

LiveView::LiveView(LiveViewOptions options)
    : options_(options),
      trajectory_(options.max_trajectory_poses),
      ground_truth_(options.max_trajectory_poses) {}

void LiveView::publishFrame(const RunStatus& status, const std::optional<SE3d>& camera,
                            const std::optional<SE3d>& ground_truth) {
  MutexLock lock(frame_mutex_);
  ++version_;
  status_ = status;
  if (camera) {
    camera_ = camera;
    trajectory_.add(camera->translation());
    if (ground_truth && !ground_truth_anchor_)
      ground_truth_anchor_ = *camera * ground_truth->inverse();
  }
  if (ground_truth) ground_truth_.add(ground_truth->translation());
}

void LiveView::markFinished() {
  MutexLock lock(frame_mutex_);
  ++version_;
  status_.finished = true;
}

void LiveView::setRoute(std::vector<Eigen::Vector3d> checkpoints) {
  MutexLock lock(frame_mutex_);
  ++version_;
  route_ = std::move(checkpoints);
}

void LiveView::setMapSampler(MapSampler sampler) {
  MutexLock lock(map_mutex_);
  sampler_ = std::move(sampler);
  map_taken_at_.reset();
}

void LiveView::clearMapSampler() {
  MutexLock lock(map_mutex_);
  sampler_ = nullptr;
}

std::uint64_t LiveView::version() const {
  MutexLock lock(frame_mutex_);
  return version_;
}

void LiveView::refreshMapIfDue() {
  if (!sampler_) return;
  const auto now = std::chrono::steady_clock::now();
  if (map_taken_at_ && now - *map_taken_at_ < options_.map_refresh) return;
  map_ = sampler_(options_.max_points);
  if (map_.keyframe_poses.size() > options_.max_keyframes) {
    // Evenly spaced, the newest kept.
    std::vector<SE3d> kept;
    kept.reserve(options_.max_keyframes);
    const std::size_t n = map_.keyframe_poses.size();
    for (std::size_t i = 0; i < options_.max_keyframes; ++i) {
      kept.push_back(map_.keyframe_poses[n - 1 - i * n / options_.max_keyframes]);
    }
    std::reverse(kept.begin(), kept.end());
    map_.keyframe_poses = std::move(kept);
    map_.keyframe_ids.clear();  // not shown
  }
  map_taken_at_ = now;
  ++map_generation_;
}

ViewSnapshot LiveView::snapshotLocked() {
  ViewSnapshot out;
  {
    MutexLock lock(frame_mutex_);
    out.version = version_;
    out.status = status_;
    if (camera_) out.camera = ViewPose{camera_->translation(), camera_->rotation()};
    out.trajectory = trajectory_.positions();
    out.route = route_;
    if (ground_truth_anchor_) {
      out.ground_truth.reserve(ground_truth_.positions().size());
      for (const Eigen::Vector3d& p : ground_truth_.positions()) {
        out.ground_truth.push_back(*ground_truth_anchor_ * p);
      }
    }
  }
  out.keyframes.reserve(map_.keyframe_poses.size());
  for (const SE3d& pose : map_.keyframe_poses) {
    out.keyframes.push_back({pose.translation(), pose.rotation()});
  }
  out.points = map_.points;
  out.points_total = map_.total_points;
  return out;
}

ViewSnapshot LiveView::snapshot() {
  MutexLock lock(map_mutex_);
  refreshMapIfDue();
  return snapshotLocked();
}

std::string LiveView::snapshotJson() {
  MutexLock lock(map_mutex_);
  refreshMapIfDue();
  const auto key = std::make_pair(version(), map_generation_);
  if (encoded_for_ != key) {
    const ViewSnapshot snapshot = snapshotLocked();
    encoded_ = toJson(snapshot).dump();
    encoded_for_ = std::make_pair(snapshot.version, map_generation_);
  }
  return encoded_;
}

}  // namespace edgeslam::viz
