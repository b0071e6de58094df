#pragma once
// Local mapping: takes keyframes from tracking and, on its own thread, links their points, culls
// weak recent points, triangulates new points with neighbour keyframes, fuses duplicates, runs
// local bundle adjustment and removes redundant keyframes. Every map change goes through Map under
// its mutex.
#include <atomic>
#include <cstddef>
#include <functional>
#include <list>
#include <memory>
#include <optional>
#include <string_view>

#include "geometry/camera.h"
#include "map/keyframe_sink.h"
#include "map/map.h"
#include "map/map_participant.h"
#include "map/pair_triangulation.h"
#include "optimize/map_optimization.h"
#include "place/vocabulary.h"
#include "util/mutex.h"
#include "util/queued_worker.h"
#include "util/thread_annotations.h"
#include "util/timing_stats.h"

namespace edgeslam {

// How triangulation finds keypoint pairs between a keyframe and its neighbours: through their
// bag-of-words direct indexes (map_matching.h matchForTriangulationByBow), or every unmatched
// keypoint against the whole epipolar band (matchForTriangulation).
enum class TriangulationSearch { kBagOfWords, kEpipolarBand };

std::string_view toString(TriangulationSearch search);
// "bow" or "band"; nullopt otherwise.
std::optional<TriangulationSearch> parseTriangulationSearch(std::string_view text);

struct LocalMapperOptions {
  bool monocular = true;
  std::size_t triangulation_neighbours_mono = 20;
  std::size_t triangulation_neighbours_depth = 10;
  std::size_t fusion_neighbours_mono = 20;
  std::size_t fusion_neighbours_depth = 10;
  // Best/second-best ratio of the epipolar descriptor search.
  float triangulation_ratio = 0.6f;
  // Rays closer than this give no monocular point (pair_triangulation.h says why not 1.15).
  double min_triangulation_parallax_deg = kDefaultMinTriangulationParallaxDeg;
  // kBagOfWords needs `vocabulary`; without one the band search is used.
  TriangulationSearch triangulation_search = TriangulationSearch::kBagOfWords;
  // With kBagOfWords, every keyframe is described (bag of words and direct index at
  // `direct_index_depth`, stored on the KeyFrame, where loop closing finds it) before
  // triangulation.
  std::shared_ptr<const Vocabulary> vocabulary;
  int direct_index_depth = 2;    // as loop detection's, so that its description is reused
  std::size_t max_queue = 3;     // tracking is asked to wait beyond this backlog
  double redundant_ratio = 0.9;  // a keyframe whose points are 90 % seen by 3+ others is culled
  bool run_local_ba = true;
  // Across a network the client makes its next keyframe before it has the points the edge just
  // triangulated, so the keyframe cannot observe them: search it for the recent points before
  // culling those as unobserved.
  bool observe_recent_points = false;
  bool cull_keyframes = true;
  // Revisits: a new keyframe that sees what an older keyframe (made at least
  // `revisit_min_frames` frames before) saw from about the same viewpoint (camera centres closer
  // than `revisit_distance_ratio` x the new keyframe's median scene depth, optical axes within
  // `revisit_max_angle_deg`, at least `revisit_min_shared_points` points in common) is culled:
  // a camera going over mapped ground again does not grow the map. The redundancy rule above
  // rarely fires there, as each RGB-D keyframe brings hundreds of fresh depth points.
  bool cull_revisits = true;
  std::size_t revisit_min_frames = 150;
  double revisit_distance_ratio = 0.1;
  double revisit_max_angle_deg = 15.0;
  int revisit_min_shared_points = 30;
  // Nice increment for the mapping thread (util/thread_priority.h); 0 leaves it as it is.
  int thread_nice = 0;
};

struct LocalMapperStats {
  std::size_t keyframes_processed = 0;
  std::size_t points_created = 0;
  std::size_t points_culled = 0;
  std::size_t keyframes_culled = 0;
  std::size_t revisit_keyframes_culled = 0;  // of keyframes_culled, new keyframes on revisits
  std::size_t local_ba_runs = 0;
  // Triangulation searches (and how many went through bag of words), the pairs they proposed and
  // their total wall time.
  std::size_t triangulation_searches = 0;
  std::size_t triangulation_bow_searches = 0;
  std::size_t triangulation_pairs = 0;
  double triangulation_search_ms = 0.0;
  // Wall time of mapping each keyframe (waits for the map's lock included), and of its local BA.
  SampleStats keyframe_ms;
  SampleStats local_ba_ms;
};

// Of a keyframe's points (with depth: its close points), those seen at the same or a finer scale
// by at least three other keyframes.
struct KeyFrameRedundancy {
  std::size_t points = 0;
  std::size_t redundant = 0;
};

class LocalMapper : public KeyFrameSink {
 public:
  LocalMapper(Map& map, const PinholeCamera& camera, LocalMapperOptions options);
  ~LocalMapper() override;

  // Runs on its own thread until stop(); without start(), call processAll() to map synchronously.
  // An exception on the thread ends it: failure() says why, keyframes are no longer taken and
  // waitUntilIdle() returns (the owner ends its session or run).
  void start();
  void stop();
  void processAll();
  void waitUntilIdle();

  void insertKeyFrame(KeyFrame* keyframe) override;
  // The keyframe's bag of words and direct index (once; no-op without bag-of-words search).
  void describe(KeyFrame* keyframe) const;
  bool acceptsKeyFrames() const override;
  std::size_t lastOptimizedFrame() const override { return last_optimized_frame_.load(); }
  void onMapReset() override;

  LocalMapperStats stats() const;
  std::optional<std::string> failure() const { return queue_.failure(); }

  // Loop closing: stops mapping between keyframes (a running local BA is aborted) until resume().
  // Returns once the mapping thread is idle; without a thread there is nothing to wait for.
  void pause();
  void resume();

  // Called on the mapping thread after each keyframe is mapped (set before start()).
  void setKeyFrameMappedCallback(std::function<void(KeyFrame*)> callback) {
    on_mapped_ = std::move(callback);
  }

 private:
  // The queue's work: one keyframe, then erased points released.
  void mapNext(KeyFrame* keyframe);
  void processKeyFrame(KeyFrame* keyframe);
  void mapKeyFrame(KeyFrame* keyframe);
  void linkKeyFrame(KeyFrame* keyframe) REQUIRES(map_.updateMutex());
  void observeRecentPoints(KeyFrame* keyframe) REQUIRES(map_.updateMutex());
  void cullRecentPoints(KeyFrame* keyframe) REQUIRES(map_.updateMutex());
  bool searchesByBow() const;
  void createNewPoints(KeyFrame* keyframe);
  void fuseWithNeighbours(KeyFrame* keyframe);
  void cullKeyFrames(KeyFrame* keyframe);
  KeyFrameRedundancy redundancy(const KeyFrame& keyframe) const;  // under the map's mutex
  // Culls `keyframe` itself when an older keyframe covers its view (cull_revisits).
  bool cullRevisit(KeyFrame* keyframe);
  bool hasPending(KeyFrame* keyframe) const;  // a keyframe of its client waits
  // Between keyframes: lets go of erased points so that the map can free them.
  void releaseErased();

  Map& map_;
  const PinholeCamera& camera_;
  LocalMapperOptions options_;
  MapParticipant map_participant_;

  std::atomic<bool> reset_requested_{false};
  std::atomic<std::size_t> last_optimized_frame_{0};
  std::list<MapPoint*> recent_points_;
  mutable Mutex stats_mutex_;
  LocalMapperStats stats_ GUARDED_BY(stats_mutex_);
  std::function<void(KeyFrame*)> on_mapped_;
  // Last: its thread, which uses everything above, ends before any of it is destroyed. Its
  // giveWay() flag aborts a running local BA (a new keyframe of the same client, pause(), stop()).
  QueuedWorker<KeyFrame*> queue_;
};

}  // namespace edgeslam
