#pragma once
// What every run mode shares: feature extraction and tracking on the caller's thread against the
// client's map, the trajectories and the counters. Modes differ in where keyframes go (local
// mapping in-process, or the edge) and in what they count.
#include <cstdint>
#include <functional>
#include <memory>
#include <opencv2/core.hpp>
#include <optional>
#include <utility>
#include <vector>

#include "adapt/compute_budget.h"
#include "client/segmentation_refresh.h"
#include "client/semantic_frame_filter.h"
#include "client/tracker.h"
#include "features/frame_features_builder.h"
#include "features/orb_extractor.h"
#include "io/trajectory.h"
#include "map/map.h"
#include "mapping/mapping_backend.h"
#include "modes/first_map_frame.h"
#include "modes/paced_keyframe_sink.h"
#include "modes/slam_counters.h"
#include "modes/split_client_report.h"
#include "optimize/map_optimization.h"
#include "place/vocabulary.h"
#include "semantic/segmenter.h"
#include "util/timing_stats.h"

namespace edgeslam {

class AdaptationLoop;

struct SlamOptions {
  Sensor sensor = Sensor::kMonocular;
  OrbExtractorOptions orb;
  TrackerOptions tracker;
  // Edge mode, monocular: tracking triangulates new points at each keyframe (sets
  // tracker.triangulate_at_keyframes) instead of waiting for the edge's; local mode ignores it.
  bool client_triangulation = true;
  DepthOptions depth;
  // The mapping back end (mapping/mapping_backend.h). Local mode runs it in-process (its sensor is
  // `sensor`); edge mode's run gives its mapper, vocabulary and loop-closing options to the edge
  // session, which runs the same back end. Loop closing needs a vocabulary. Local mode:
  // backend.threaded = false maps each keyframe before the next frame; backend.thread_nice lowers
  // mapping and loop closing so that, on a shared core, a frame is tracked before the background
  // work (util/thread_priority.h), worth it when frames come at a camera's pace (with frames fed
  // back to back the mapper would fall behind); backend.segmenter segments keyframes when
  // `semantic` is on.
  MappingBackendOptions backend;
  // Frames fed back to back (`--fast`): tracking hands over a keyframe only once the back end (the
  // local mapper and segmentation, or the edge) has finished the previous one, so the map does not
  // depend on the machine's speed (modes/paced_keyframe_sink.h).
  bool wait_for_backend = false;
  // Semantic culling (paper Sec. IV-C): keyframes are segmented (local mode: by
  // backend.segmenter, on a thread of its own; edge mode: on the edge, from the image sent with
  // the upload) and each frame's features on the movable objects, found by transferring the
  // latest keyframe mask, are culled before tracking.
  bool semantic = false;
  SemanticFilterOptions semantic_filter;
  int keyframe_image_reduce = 2;  // keyframes are segmented at 1/this of full size
  // With semantic culling: how many frames (of a 30 fps camera) at most between keyframes, so
  // that people walking into view are segmented soon; the interval follows the masks' delay
  // (client/segmentation_refresh.h, KeyFrameParameters::segmentation_refresh).
  SegmentationRefreshOptions segmentation_refresh;
  // Local mode: when the run finishes, a self-calibrating global bundle adjustment refines the
  // focal length and radial distortion from the map itself and, where the data asks for it,
  // re-solves the map with them (optimize/intrinsics_refinement.h).
  bool refine_intrinsics = true;
  IntrinsicsRefinementOptions intrinsics_refinement;
};

// Nice 10 gives a thread about a tenth of the CPU against a nice-0 one.
inline constexpr int kBackgroundNiceWhenPaced = 10;

// Edge mode's client extracts at most this many features: an upload costs about 37 bytes per
// feature (a 32-byte descriptor, ~5 bytes of keypoint), so a keyframe stays within ~60 KB. On KITTI
// 07 (2000 features otherwise) it took uploads from 72 to 58 KB, with the ATE of 3 runs each
// within their spread (33.3 [29.8-37.0] cm against 34.3 [33.2-34.7]).
inline constexpr int kEdgeClientMaxFeatures = 1600;

// Sensible defaults for a camera: 1000 features up to 640x480-ish, 2000 for wide images (KITTI).
SlamOptions defaultSlamOptions(const PinholeCamera& camera, Sensor sensor);

// Where one frame's client time went (zero where the client does not track: offload).
struct ClientStageTimes {
  double features_ms = 0.0;  // ORB extraction, undistortion, depth lookup (and semantic culling)
  double tracking_ms = 0.0;  // pose estimation and local-map tracking
  double keyframe_ms = 0.0;  // keyframe insertion, upload and the rest of the frame
};

// Bytes over the link so far (zero in local mode).
struct LinkTraffic {
  std::uint64_t uplink_bytes = 0;
  std::uint64_t downlink_bytes = 0;
};

// A bounded look at the client's map for display.
struct MapSample {
  std::vector<SE3d> keyframe_poses;      // camera-to-world, by keyframe id
  std::vector<KeyFrameId> keyframe_ids;  // of keyframe_poses, one each
  std::vector<Eigen::Vector3d> points;
  std::size_t total_points = 0;  // in the client's map, of which `points` is a subsample
};

// The frame-time poses of a map started after tracking was lost for good, in that map's own frame
// (before a merge moved it onto the first map, or for good when none did).
struct OwnMapTrajectory {
  std::uint32_t map = 0;  // k: the k-th map started (SlamSystem::mapsStartedAt()[k - 1])
  Trajectory poses;
  std::size_t never_joined = 0;  // of them, frames whose map no merge joined to the first
};

// One run mode's whole SLAM as the run command drives it.
class SlamSystem {
 public:
  virtual ~SlamSystem() = default;

  // `depth` is CV_32FC1 metres (RGB-D) or empty; `color` (BGR, optional) is what keyframes are
  // segmented on when semantic culling is on (else `gray`).
  // (Overrides repeat the default.)
  virtual TrackResult process(std::size_t frame_index, double timestamp, const cv::Mat& gray,
                              const cv::Mat& depth, const cv::Mat& color = cv::Mat()) = 0;
  // Lets mapping finish its backlog (call before reading the final trajectory).
  virtual void finish() = 0;
  virtual SlamCounters counters() const { return {}; }
  // Cheap (no statistics): fit for every frame.
  virtual LinkTraffic linkTraffic() const { return {}; }
  virtual const char* modeName() const = 0;
  // The client's map (in edge mode the window it holds), at most `max_points` points; safe from
  // any thread while the run goes on. Empty where the client has no map (offload).
  virtual MapSample mapSample(std::size_t /*max_points*/) const { return {}; }
  // The end-of-run intrinsics refinement, once finish() has run it (local mode).
  virtual std::optional<MapIntrinsicsRefinement> intrinsicsRefinement() const {
    return std::nullopt;
  }

  // Pose of every tracked frame as it was estimated at that frame's time, in the frame of the map
  // the run began with (FirstMapFrame: frames of a map of its own are left out).
  virtual Trajectory trajectoryAtFrameTime() const = 0;
  // Every tracked frame relative to its reference keyframe's final pose, where that is in the
  // first map's frame.
  virtual Trajectory trajectoryFinal() const = 0;
  // What trajectoryAtFrameTime() left out, by map (in order of their first frame).
  virtual std::vector<OwnMapTrajectory> trajectoriesInOwnFrames() const { return {}; }
  virtual Trajectory keyframeTrajectory() const = 0;
  virtual std::size_t keyFrameCount() const = 0;
  virtual std::size_t mapPointCount() const = 0;
  virtual std::size_t relocalizations() const = 0;
  // Times tracking came back by its motion prediction after a few lost frames.
  virtual std::size_t trackingRecoveries() const { return 0; }
  // Keyframes the client's tracker made, by rule (zeros where the client does not track).
  virtual KeyFrameDecisionCounts keyFrameDecisions() const { return {}; }
  // Why frames had no map or were lost, per cause (nullopt where the client does not track).
  virtual std::optional<TrackingDiagnostics> trackingDiagnostics() const { return std::nullopt; }
  virtual std::size_t mapResets() const = 0;
  // Frames at which a new map was started beside the old one, tracking lost for good.
  virtual std::vector<std::size_t> mapsStartedAt() const { return {}; }
  // The last frame's semantic stage (mask, culled features); nullptr where the client does not
  // track (offload).
  virtual const SemanticFrame* lastSemanticFrame() const { return nullptr; }
  virtual ClientStageTimes lastFrameStages() const { return {}; }

  // The client's cost fitted to its CPU (adapt/compute_budget.h): the extraction of the frames
  // after this one follows `step`. False where the client extracts nothing (offload).
  virtual bool setComputeStep(const ComputeStep& /*step*/) { return false; }
  // Features and pyramid levels the next frame is extracted with (0, 0 where none).
  virtual std::pair<int, int> extractionSize() const { return {0, 0}; }

  // What a mode alone has; absent elsewhere. The loop that retunes the keyframe rules to the link
  // (edge mode with adaptation):
  virtual const AdaptationLoop* adaptation() const { return nullptr; }
  // The client's side of the split (edge mode):
  virtual std::optional<SplitClientReport> splitClientReport() const { return std::nullopt; }
};

// Modes that track on the client against the client's map: feature extraction and tracking on the
// caller's thread; subclasses decide where keyframes go.
class TrackingSlam : public SlamSystem {
 public:
  TrackingSlam(const TrackingSlam&) = delete;
  TrackingSlam& operator=(const TrackingSlam&) = delete;

  TrackResult process(std::size_t frame_index, double timestamp, const cv::Mat& gray,
                      const cv::Mat& depth, const cv::Mat& color = cv::Mat()) override;
  Trajectory trajectoryAtFrameTime() const override;
  Trajectory trajectoryFinal() const override;
  std::vector<OwnMapTrajectory> trajectoriesInOwnFrames() const override;
  Trajectory keyframeTrajectory() const override;
  std::size_t keyFrameCount() const override;
  std::size_t mapPointCount() const override;
  MapSample mapSample(std::size_t max_points) const override;
  std::size_t relocalizations() const override { return tracker_->relocalizations(); }
  std::size_t trackingRecoveries() const override { return tracker_->recoveries(); }
  KeyFrameDecisionCounts keyFrameDecisions() const override {
    return tracker_->keyFrameDecisions();
  }
  std::optional<TrackingDiagnostics> trackingDiagnostics() const override {
    return tracker_->diagnostics();
  }
  std::size_t mapResets() const override { return tracker_->resets(); }
  std::vector<std::size_t> mapsStartedAt() const override { return tracker_->mapsStartedAt(); }
  // Always present: without semantic culling, every feature is kept and there is no mask.
  const SemanticFrame* lastSemanticFrame() const override { return &last_semantic_; }
  ClientStageTimes lastFrameStages() const override { return last_stages_; }
  bool setComputeStep(const ComputeStep& step) override;
  std::pair<int, int> extractionSize() const override {
    return {extractor_.options().num_features, extractor_.numLevels()};
  }

  const Tracker& tracker() const { return *tracker_; }
  // Tracking's time spent waiting for the back end so far (offline pacing; 0 without it).
  double backendWaitTotalMs() const { return paced_sink_ ? paced_sink_->waitTotalMs() : 0.0; }
  // The client's map (lock its update mutex while reading it during a run).
  const Map& map() const { return map_; }

 protected:
  TrackingSlam(const PinholeCamera& camera, SlamOptions options, std::uint8_t map_id_origin);
  // `wait_until_idle` blocks until the back end has taken and finished every keyframe given to it;
  // tracking calls it before handing over the next keyframe when options_.wait_for_backend.
  void startTracking(KeyFrameSink* sink, std::function<void()> wait_until_idle = {});
  // Offline pacing (options_.wait_for_backend): blocks on `wait`, counted as a wait for the back
  // end; nothing otherwise.
  void waitForBackend(const std::function<void()>& wait);
  // With semantic culling, before the frame's features are culled: a mode may segment the frame
  // first, so that its own mask is the one applied.
  virtual void beforeCulling(std::size_t /*frame_index*/, const cv::Mat& /*image*/) {}
  // Before tracking a frame whose image is `image` (colour when given, else grey).
  virtual void beforeTracking(std::size_t /*frame_index*/, const cv::Mat& /*image*/) {}
  virtual void afterFrame() {}
  virtual void afterTracking(const TrackResult& /*result*/, std::size_t /*frame_index*/,
                             const cv::Mat& /*image*/) {}
  // The features the last frame was tracked with (after semantic culling).
  const std::shared_ptr<const FrameFeatures>& lastFrameFeatures() const {
    return last_semantic_.kept;
  }
  // The semantic stage's and the per-stage timing figures, for the subclasses' counters().
  void addClientCounters(SlamCounters& counters) const;
  // The pyramid the mode asks for (edge mode: Table I's row); the compute step may cap it.
  void setPyramidLevels(int levels);

  PinholeCamera camera_;
  SlamOptions options_;
  OrbExtractor extractor_;
  Map map_;
  std::unique_ptr<Tracker> tracker_;
  std::unique_ptr<SemanticFrameFilter> semantic_filter_;  // with semantic culling
  FirstMapFrame first_map_frame_;  // subclasses tell it of merges that join the first map

 private:
  SemanticFrame last_semantic_;
  SampleStats semantic_ms_;
  ClientStageTimes last_stages_;
  SampleStats features_ms_;
  SampleStats tracking_ms_;
  SampleStats keyframe_ms_;
  void noteKeyFrameDepth(KeyFrameId id);
  double keyFrameDepthRatio() const;
  static constexpr std::size_t kMinPointsForDepth = 20;
  static constexpr std::size_t kMinKeyFramesPerQuarter = 5;

  void applyExtractionSize();
  int levels_wanted_ = 0;  // of the mode; features: options_.orb.num_features
  ComputeStep compute_step_;

  std::unique_ptr<PacedKeyFrameSink> paced_sink_;
  std::vector<double> keyframe_depths_;  // monocular: each keyframe's median point depth
};

}  // namespace edgeslam
