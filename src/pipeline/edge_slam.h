#pragma once
// `--mode edge` on the client side: tracking and keyframe decisions here, mapping on the edge. New
// keyframes go up through the link; the edge's slices are applied to the client's map on the
// link's thread, so tracking never waits for the network.
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "client/edge_keyframe_sink.h"
#include "pipeline/adaptation_loop.h"
#include "pipeline/edge_link.h"
#include "pipeline/slam_system.h"

namespace edgeslam {

// The client's own map (bounded or not): what it holds now and the most it held.
struct ClientMapSize {
  std::size_t keyframes = 0;  // held: with features and points (not evicted)
  std::size_t points = 0;
  std::size_t max_keyframes = 0;
  std::size_t max_points = 0;
  std::size_t keyframes_evicted = 0;  // evictions applied over the run
  std::size_t keyframes_entered = 0;  // keyframes sent back into the window
};

// What full resyncs (a reconnection after the edge lost its session) did to the client's
// keyframes: each one the client made is on the edge, re-sent, or lost for a reason counted here.
struct ResyncCounters {
  std::uint64_t full_resyncs = 0;      // slices with full_resync applied
  std::uint64_t keyframes_resent = 0;  // the edge lacked them: uploaded again
  // The edge lacked them and the client no longer had their features (evicted from its bounded
  // map before the edge stored them): lost.
  std::uint64_t keyframes_lost_evicted = 0;
  // This client's keyframes the edge erased (culled as redundant, on a revisit say): neither in
  // the edge map nor lost.
  std::uint64_t keyframes_culled_by_edge = 0;
};

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
  const AdaptationLoop* adaptation() const { return adaptation_.get(); }
  const char* modeName() const override { return "edge"; }
  // The global map on the edge as the last slice reported it (the client's own map until then;
  // with a bounded client map the client holds only a part of it).
  std::size_t keyFrameCount() const override;
  std::size_t mapPointCount() const override;
  ClientMapSize clientMapSize() const;
  ResyncCounters resyncCounters() const;
  // Points the client triangulated itself (monocular); read once the run is over.
  const KeyFrameTriangulationStats& clientTriangulation() const;

  double finish_timeout_s = 30.0;

 private:
  void onSlice(MapSlice slice);
  void onUploadDropped(std::uint64_t sequence, KeyFrameId keyframe);
  void offerMask(const MaskRecord& mask);
  void onFullResync(const std::vector<KeyFrameId>& edge_lacks);
  void afterFrame() override;
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
  mutable std::mutex stats_mutex_;
  SampleStats slice_latency_ms_;
  SampleStats slice_apply_ms_;
  std::uint64_t slices_applied_ = 0;
  std::uint64_t loops_ = 0;
  std::uint64_t keyframes_segmented_ = 0;
  SampleStats segmentation_ms_;
  std::uint64_t edge_map_keyframes_ = 0;  // as the last slice said (0 = not said)
  std::uint64_t edge_map_points_ = 0;
  ClientMapSize client_map_;
  // Keyframes forgotten after their upload was dropped, for the tracker's relocalisation
  // database (told on the tracking thread, between frames).
  std::vector<KeyFrameId> forgotten_keyframes_;
  // Keyframes a full resync found missing on the edge, re-sent on the tracking thread.
  std::vector<KeyFrameId> keyframes_to_resend_;
  ResyncCounters resync_;
  // This client's keyframe ids: of the link's origin, above what the edge held when it opened.
  std::uint8_t own_id_origin_ = 0;
  KeyFrameId own_ids_above_ = 0;
};

}  // namespace edgeslam
