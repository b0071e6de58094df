#pragma once
// Camera tracking against the map at frame rate: initialisation, constant-velocity motion model
// with guided projection search, reference-keyframe fallback, local-map tracking, pose-only
// optimisation, the keyframe decision and keyframe creation. One instance per camera; not
// thread-safe itself, but it holds the map's update mutex while it reads or changes the map, so a
// mapper may run beside it.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "client/keyframe_policy.h"
#include "client/monocular_initializer.h"
#include "client/tracking_diagnostics.h"
#include "client/tracking_types.h"
#include "geometry/camera.h"
#include "map/frame.h"
#include "map/map.h"
#include "map/map_participant.h"
#include "map/pair_triangulation.h"
#include "relocalize/frame_relocalization.h"
#include "relocalize/keyframe_places.h"
#include "util/timing_stats.h"

namespace edgeslam {

struct TrackerOptions {
  Sensor sensor = Sensor::kMonocular;
  KeyFrameParameters keyframes;
  MonocularInitializerOptions monocular_init;
  int rgbd_init_min_features = 500;
  // RGB-D: keypoints closer than this (metres) become points at keyframe creation ("close" depth).
  float close_depth_m = 3.2f;
  // A lost frame with fewer features than this is counted as lost to "too few features" (blank,
  // overexposed, textureless) rather than to a tracking failure.
  std::size_t min_trackable_features = 100;
  int min_inliers_motion = 10;
  int min_inliers_local_map = 30;
  int min_inliers_local_map_after_relocalization = 50;
  std::size_t max_local_keyframes = 80;
  // With a vocabulary, relocalisation looks up similar keyframes in a bag-of-words database;
  // without, it tries the most recent keyframes only.
  std::shared_ptr<const Vocabulary> vocabulary;
  std::size_t relocalization_candidates = 10;
  // Time one lost frame may spend trying candidates (each a matching and a PnP RANSAC of up to
  // 200 iterations): without it a lost client took up to 0.8 s per frame, fell seconds behind a
  // live camera and never caught up (7-Scenes behind an LTE link: end-to-end median 1.75 s).
  double relocalization_budget_ms = 25.0;
  // After tracking fails, for this many frames the camera is assumed to keep the velocity it had,
  // and each frame first searches the last tracked frame's points around that prediction (before
  // relocalisation). A thin stretch of map (people walking through the view, the edge's points
  // still on their way) then costs a few frames instead of the rest of the run: the client's map
  // window holds only the keyframes near the camera, so relocalisation finds nothing once the
  // camera has moved on. 0 = off.
  std::size_t recover_within_frames = 30;
  // Monocular: each new keyframe triangulates new points with its best covisible keyframes right
  // away, so that tracking has fresh points before any mapper's come back (edge mode, where the
  // edge's points arrive a link round trip later). Local mode leaves it to local mapping.
  bool triangulate_at_keyframes = false;
  // Best covisible keyframes searched: through bag of words (a vocabulary: ~1 ms per keyframe
  // pair on KITTI's 2000 features), else across the whole epipolar band (~6 ms per pair), so
  // fewer then.
  std::size_t triangulation_neighbours = 2;
  std::size_t triangulation_neighbours_without_bow = 1;
  float triangulation_ratio = 0.6f;  // best/second-best ratio of the pair search
  double min_triangulation_parallax_deg = kDefaultMinTriangulationParallaxDeg;
  // Fill TrackResult::features_on_map / features_new (a viewer draws them; off, nothing is copied).
  bool report_feature_positions = false;
  // Localisation in a map made earlier (Tracker::localizeInMap): no keyframes are made and the map
  // is never reset, so tracking changes nothing in it but its points' seen/found counts.
  bool localization_only = false;
  // Lost this long (seconds of the camera's time) with relocalisation failing throughout, tracking
  // starts a new map beside the old one in the same Map: the old keyframes stay, and loop closing
  // merges the two when the camera sees the old places again (mapping/map_part_merge.h). A camera
  // that never comes back would otherwise wait for good. 0 = never (wait for relocalisation): the
  // default, since until a merge (or for good, without one) the new map's poses are in a frame of
  // their own in the trajectory at frame time.
  double new_map_after_lost_s = 0.0;
};

// What triangulating at keyframes did (TrackerOptions::triangulate_at_keyframes).
struct KeyFrameTriangulationStats {
  std::size_t keyframes = 0;
  std::size_t searches = 0;  // keyframe pairs searched
  std::size_t bow_searches = 0;
  std::size_t pairs = 0;  // keypoint pairs proposed
  std::size_t points_created = 0;
  SampleStats ms;  // per keyframe: search, triangulation and point creation
};

class Tracker {
 public:
  Tracker(Map& map, const PinholeCamera& camera, TrackerOptions options, KeyFrameSink* sink);

  TrackResult track(std::size_t frame_index, double timestamp,
                    std::shared_ptr<const FrameFeatures> features);

  // Localisation only: the map already holds a map made earlier (loaded before the first frame).
  // Its keyframes go into the relocalisation database and tracking starts lost, so that the first
  // frames relocalise in it. Needs a vocabulary; throws std::invalid_argument otherwise.
  void localizeInMap();

  TrackingState state() const { return state_; }
  const TrackerOptions& options() const { return options_; }
  KeyFrameParameters& keyframeParameters() { return options_.keyframes; }

  // Per processed frame: the reference keyframe and the frame's pose relative to it, so that the
  // final trajectory follows later corrections of the keyframes.
  struct FrameRecord {
    std::size_t index = 0;
    double timestamp = 0.0;
    bool tracked = false;
    KeyFrame* reference = nullptr;
    SE3d T_cr;  // camera-from-reference-keyframe
    SE3d T_cw;  // the pose estimated at the frame's time
    // The map the frame was tracked in: 0 the first, k the k-th started after tracking was lost
    // for good (mapsStartedAt()[k - 1]).
    std::uint32_t map = 0;
  };
  const std::vector<FrameRecord>& records() const { return records_; }
  // The edge moved the client's bounded map window: evicted keyframes leave the relocalisation
  // database and keyframes back in the window join it again, so relocalisation searches the
  // window only. Takes the map's update mutex (call from any thread, not inside track()).
  void onMapWindowChanged(const std::vector<KeyFrameId>& evicted,
                          const std::vector<KeyFrameId>& entered);
  // Localisation through the edge: the map arrives in slices (none yet), and tracking starts lost
  // so that no map of its own is begun. Relocalisation needs no vocabulary here: the edge finds
  // the place (relocalizeNear).
  void localizeInArrivingMap();
  // The edge relocalised a recent frame against this keyframe (held in the client's map): the next
  // lost frames try it and its neighbours first.
  void relocalizeNear(KeyFrameId keyframe) { relocalization_hint_ = keyframe; }
  // Keyframes in the relocalisation database (0 without a vocabulary).
  std::size_t placesSize() const;
  std::size_t relocalizations() const { return relocalizations_; }
  // Times tracking came back by the motion prediction (TrackerOptions::recover_within_frames).
  std::size_t recoveries() const { return recoveries_; }
  std::size_t resets() const { return resets_; }
  // New maps started beside the old one after tracking was lost for good
  // (TrackerOptions::new_map_after_lost_s), and the frames they were started at.
  std::size_t mapsStarted() const { return maps_started_at_.size(); }
  const std::vector<std::size_t>& mapsStartedAt() const { return maps_started_at_; }
  // Keyframes made so far, by the rule that made them.
  const KeyFrameDecisionCounts& keyFrameDecisions() const { return keyframe_decisions_; }
  const KeyFrameTriangulationStats& triangulationStats() const { return triangulation_; }
  // Why frames had no map or no pose, per cause.
  const TrackingDiagnostics& diagnostics() const { return diagnostics_; }

 private:
  bool initialize(Frame& frame);
  bool initializeRgbd(Frame& frame);
  // The last tracked frame's points projected from the pose its velocity predicts `steps`
  // frames on (more than one: across lost frames).
  bool trackWithMotionModel(Frame& frame, std::size_t steps = 1);
  bool trackReferenceKeyFrame(Frame& frame);
  bool canRecoverByPrediction(std::size_t frame_index) const;
  bool relocalize(Frame& frame) REQUIRES(map_.updateMutex());
  std::vector<KeyFrame*> relocalizationCandidates(const Frame& frame) REQUIRES(map_.updateMutex());
  void remember(KeyFrame* keyframe);
  int trackLocalMap(Frame& frame);
  void updateLocalMap(const Frame& frame);
  void addPointsFromLastFrameDepth(Frame& last);
  KeyFrameDecision decide(const Frame& frame, int inliers) const REQUIRES(map_.updateMutex());
  KeyFrame* createKeyFrame(Frame& frame) REQUIRES(map_.updateMutex());
  void triangulateAtKeyFrame(KeyFrame* keyframe, Frame& frame) REQUIRES(map_.updateMutex());
  void record(const Frame& frame, bool tracked);
  void resetMap();
  // Lost for good: the next frames initialise a new map beside the old one (kept, with its
  // relocalisation database).
  void startNewMap(const Frame& frame);
  // Tracking starts again from no map: state, last frame, motion, reference keyframe, local map
  // and the loss clock forgotten (the map itself is the caller's).
  void forgetTrackingState();
  // Keyframes of the map tracking works in now (the newest part when maps were started).
  std::size_t currentMapKeyFrames() const REQUIRES(map_.updateMutex());
  // Under the map's mutex, at the start of each frame: lets go of erased points and keyframes so
  // that the map can free them (MapParticipant).
  void releaseErased() REQUIRES(map_.updateMutex());
  void reportFeaturePositions(const Frame& frame, TrackResult& result) const;

  Map& map_;
  const PinholeCamera& camera_;
  TrackerOptions options_;
  KeyFrameSink* sink_;
  MonocularInitializer mono_init_;
  std::unique_ptr<KeyFramePlaces> places_;
  MapParticipant map_participant_;

  TrackingState state_ = TrackingState::kNotInitialized;
  std::optional<Frame> last_frame_;
  std::optional<SE3d> velocity_;  // T_cw(current) * T_wc(last)
  KeyFrame* reference_keyframe_ = nullptr;
  std::size_t last_keyframe_frame_ = 0;
  std::size_t last_relocalization_frame_ = 0;
  KeyFrameId relocalization_hint_ = kInvalidId;
  static constexpr std::size_t kRelocalizationHintNeighbours = 5;
  std::vector<KeyFrame*> local_keyframes_;
  std::vector<MapPoint*> local_points_;
  std::vector<FrameRecord> records_;
  std::size_t relocalizations_ = 0;
  std::size_t recoveries_ = 0;
  KeyFrameDecisionCounts keyframe_decisions_;
  std::size_t resets_ = 0;
  std::size_t frames_lost_ = 0;
  std::optional<double> lost_since_;  // the timestamp of the first frame of the current loss
  std::vector<std::size_t> maps_started_at_;
  // The last pose tracked before a new map was started: where the new map begins, so that its
  // trajectory goes on from there until a merge puts it in the old map's frame.
  std::optional<SE3d> new_map_start_pose_;
  KeyFrameId current_map_first_keyframe_ = 0;  // ids below belong to older maps
  double current_map_initialised_at_ = 0.0;    // timestamp, s
  // A monocular map lost within this much camera time of its start is started again.
  static constexpr double kYoungMapSeconds = 1.0;
  KeyFrameTriangulationStats triangulation_;
  TrackingDiagnostics diagnostics_;
};

}  // namespace edgeslam
