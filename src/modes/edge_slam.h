#pragma once
// `--mode edge` on the client side: tracking and keyframe decisions here, mapping on the edge. New
// keyframes go up through the link; the edge's slices are applied to the client's map on the
// link's thread, so tracking never waits for the network.
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "client/edge_keyframe_sink.h"
#include "modes/adaptation_loop.h"
#include "modes/edge_link.h"
#include "modes/slam_system.h"
#include "util/mutex.h"
#include "util/thread_annotations.h"

namespace edgeslam {

class EdgeSlam : public TrackingSlam {
 public:
  // With `adaptation` and a networked link, a probing loop retunes the keyframe rules and the
  // pyramid (paper Table I) as the link changes.
  EdgeSlam(const PinholeCamera& camera, SlamOptions options, std::unique_ptr<EdgeLink> link,
           std::optional<AdaptationLoopOptions> adaptation = std::nullopt);
  ~EdgeSlam() override;

  // Waits (up to `timeout_s`) until every upload has been answered by a slice (or dropped).
  void finish() override;
  SlamCounters counters() const override;
  LinkTraffic linkTraffic() const override;
  // nullptr without adaptation.
  const AdaptationLoop* adaptation() const override { return adaptation_.get(); }
  const char* modeName() const override { return "edge"; }
  // The global map on the edge as the last slice reported it (the client's own map until then;
  // with a bounded client map the client holds only a part of it).
  std::size_t keyFrameCount() const override;
  std::size_t mapPointCount() const override;
  ClientMapSize clientMapSize() const;
  ResyncCounters resyncCounters() const;
  // Points the client triangulated itself (monocular); read once the run is over.
  const KeyFrameTriangulationStats& clientTriangulation() const;
  // Read once the run is over.
  std::optional<SplitClientReport> splitClientReport() const override {
    return SplitClientReport{clientMapSize(), resyncCounters(), clientTriangulation()};
  }

  double finish_timeout_s = 30.0;

 private:
  void onSlice(MapSlice slice);
  void onUploadDropped(std::uint64_t sequence, KeyFrameId keyframe);
  void offerMask(const MaskRecord& mask);
  void onFullResync(const std::vector<KeyFrameId>& edge_lacks);
  void afterFrame() override;
  void afterTracking(const TrackResult& result, std::size_t frame_index,
                     const cv::Mat& image) override;
  // --fast: until the edge has answered every keyframe upload (at most kMaxEdgeWaitS).
  void waitForEdge();
  static constexpr double kMaxEdgeWaitS = 10.0;
  void beforeTracking(std::size_t frame_index, const cv::Mat& image) override;
  void applyConfiguration(const KeyframeConfig& config);
  void noteClientMapSize(std::size_t keyframes, std::size_t points);

  std::unique_ptr<EdgeLink> link_;
  std::unique_ptr<EdgeKeyFrameSink> sink_;
  std::unique_ptr<AdaptationLoop> adaptation_;
  std::uint64_t applied_config_version_ = 0;
  std::uint64_t uploads_seen_ = 0;
  mutable Mutex stats_mutex_;  // guards the fields below
  SampleStats slice_latency_ms_ GUARDED_BY(stats_mutex_);
  SampleStats slice_apply_ms_ GUARDED_BY(stats_mutex_);
  std::uint64_t slices_applied_ GUARDED_BY(stats_mutex_) = 0;
  std::uint64_t loops_ GUARDED_BY(stats_mutex_) = 0;
  std::uint64_t merges_ GUARDED_BY(stats_mutex_) = 0;  // loops that moved this client's part
  std::vector<LoopFramesRecord> loop_frames_ GUARDED_BY(stats_mutex_);
  std::uint64_t keyframes_segmented_ GUARDED_BY(stats_mutex_) = 0;
  SampleStats segmentation_ms_ GUARDED_BY(stats_mutex_);
  std::uint64_t edge_map_keyframes_ GUARDED_BY(stats_mutex_) =
      0;  // as the last slice said (0 = not said)
  std::uint64_t edge_map_points_ GUARDED_BY(stats_mutex_) = 0;
  ClientMapSize client_map_ GUARDED_BY(stats_mutex_);
  // Keyframes forgotten after their upload was dropped, for the tracker's relocalisation
  // database (told on the tracking thread, between frames).
  std::vector<KeyFrameId> forgotten_keyframes_ GUARDED_BY(stats_mutex_);
  // Keyframes a full resync found missing on the edge, re-sent on the tracking thread.
  std::vector<KeyFrameId> keyframes_to_resend_ GUARDED_BY(stats_mutex_);
  ResyncCounters resync_ GUARDED_BY(stats_mutex_);
  // This client's keyframe ids: of the link's origin, above what the edge held when it opened.
  std::uint8_t own_id_origin_ = 0;
  KeyFrameId own_ids_above_ = 0;
};

}  // namespace edgeslam
