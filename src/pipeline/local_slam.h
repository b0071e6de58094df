#pragma once
// The whole SLAM in one process (`--mode local`, the ORB-SLAM baseline): feature extraction and
// tracking on the caller's thread, local mapping on its own thread, one shared map.
#include <memory>
#include <opencv2/core.hpp>

#include "client/tracker.h"
#include "edge/local_mapper.h"
#include "features/frame_features_builder.h"
#include "features/orb_extractor.h"
#include "io/trajectory.h"
#include "map/map.h"

namespace edgeslam {

struct LocalSlamOptions {
  Sensor sensor = Sensor::kMonocular;
  OrbExtractorOptions orb;
  TrackerOptions tracker;
  LocalMapperOptions mapper;
  DepthOptions depth;
  bool threaded_mapping = true;  // false: map each keyframe before the next frame (deterministic)
};

// Sensible defaults for a camera: 1000 features up to 640x480-ish, 2000 for wide images (KITTI).
LocalSlamOptions defaultLocalSlamOptions(const PinholeCamera& camera, Sensor sensor);

class LocalSlam {
 public:
  LocalSlam(const PinholeCamera& camera, LocalSlamOptions options);
  ~LocalSlam();

  // `depth` is CV_32FC1 metres (RGB-D) or empty.
  TrackResult process(std::size_t frame_index, double timestamp, const cv::Mat& gray,
                      const cv::Mat& depth);
  // Lets mapping finish its backlog (call before reading the final trajectory).
  void finish();

  // Pose of every tracked frame as it was estimated at that frame's time.
  Trajectory trajectoryAtFrameTime() const;
  // Every tracked frame relative to its reference keyframe's final pose.
  Trajectory trajectoryFinal() const;
  Trajectory keyframeTrajectory() const;

  const Tracker& tracker() const { return *tracker_; }
  const LocalMapper& mapper() const { return *mapper_; }
  std::size_t keyFrameCount() const;
  std::size_t mapPointCount() const;

 private:
  PinholeCamera camera_;
  LocalSlamOptions options_;
  OrbExtractor extractor_;
  Map map_;
  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<Tracker> tracker_;
};

}  // namespace edgeslam
