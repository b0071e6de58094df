#pragma once
// The state the web viewer serves, fed by the run loop and read by the viewer's threads.
//
// The run loop publishes each frame's figures and pose (a few numbers under a short lock: tracking
// never walks the map for the viewer). The map itself (keyframes, a sample of the points) is taken
// by the reader, through the sampler the run gives, and at most once per `map_refresh`; nothing
// is sampled or encoded while no one is watching.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "geometry/se3.h"
#include "modes/slam_system.h"
#include "util/mutex.h"
#include "viz/frame_image_slot.h"
#include "viz/trajectory_decimator.h"
#include "viz/view_snapshot.h"
#include "viz/view_source.h"

namespace edgeslam::viz {

struct LiveViewOptions {
  std::size_t max_trajectory_poses = 5000;  // per trajectory (estimate, ground truth)
  std::size_t max_points = 20000;
  std::size_t max_keyframes = 5000;
  std::chrono::milliseconds map_refresh{500};
};

// Returns the map as it is now, with at most the given number of points; called from the
// viewer's threads (so it must lock what the map needs).
using MapSampler = std::function<MapSample(std::size_t max_points)>;

class LiveView : public ViewSource {
 public:
  explicit LiveView(LiveViewOptions options = {});

  // After each frame. Poses are camera-to-world; `ground_truth` in the dataset's own frame (it is
  // drawn anchored at the first frame that has both).
  void publishFrame(const RunStatus& status, const std::optional<SE3d>& camera,
                    const std::optional<SE3d>& ground_truth);
  void markFinished();
  // The checkpoints of the route the client follows (in the trajectory's frame), once.
  void setRoute(std::vector<Eigen::Vector3d> checkpoints);
  void setMapSampler(MapSampler sampler);
  // Drops the sampler (before what it samples goes away); the last sample stays on show.
  void clearMapSampler();

  ViewSnapshot snapshot();
  // toJson(snapshot()).dump(), encoded at most once per change and shared by every reader.
  std::string snapshotJson() override;
  std::uint64_t version() const;
  // The camera image of the mobile view (/api/frame.jpg).
  FrameImageSlot* images() override { return &images_; }

 private:
  void refreshMapIfDue() REQUIRES(map_mutex_);
  ViewSnapshot snapshotLocked() REQUIRES(map_mutex_);  // the map already refreshed

  LiveViewOptions options_;
  FrameImageSlot images_;

  mutable Mutex frame_mutex_;  // what the run loop publishes
  std::uint64_t version_ GUARDED_BY(frame_mutex_) = 0;
  RunStatus status_ GUARDED_BY(frame_mutex_);
  std::optional<SE3d> camera_ GUARDED_BY(frame_mutex_);
  TrajectoryDecimator trajectory_ GUARDED_BY(frame_mutex_);
  TrajectoryDecimator ground_truth_ GUARDED_BY(frame_mutex_);
  // Trajectory frame from ground-truth frame.
  std::optional<SE3d> ground_truth_anchor_ GUARDED_BY(frame_mutex_);
  std::vector<Eigen::Vector3d> route_ GUARDED_BY(frame_mutex_);

  Mutex map_mutex_;  // the readers' side: sampler, map sample and the encoded snapshot
  MapSampler sampler_ GUARDED_BY(map_mutex_);
  MapSample map_ GUARDED_BY(map_mutex_);
  std::uint64_t map_generation_ GUARDED_BY(map_mutex_) = 0;
  std::optional<std::chrono::steady_clock::time_point> map_taken_at_ GUARDED_BY(map_mutex_);
  std::string encoded_ GUARDED_BY(map_mutex_);
  // Version, generation.
  std::optional<std::pair<std::uint64_t, std::uint64_t>> encoded_for_ GUARDED_BY(map_mutex_);
};

}  // namespace edgeslam::viz
