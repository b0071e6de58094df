#pragma once
// `--mode edge` on the client side: tracking and keyframe decisions here, mapping on the edge. New
// keyframes go up through the link; the edge's slices are applied to the client's map on the
// link's thread, so tracking never waits for the network.
#include <memory>
#include <mutex>

#include "client/edge_keyframe_sink.h"
#include "pipeline/edge_link.h"
#include "pipeline/slam_system.h"

namespace edgeslam {

class EdgeSlam : public TrackingSlam {
 public:
  EdgeSlam(const PinholeCamera& camera, SlamOptions options, std::unique_ptr<EdgeLink> link);
  ~EdgeSlam() override;

  // Waits (up to `timeout_s`) until every upload has been answered by a slice.
  void finish() override;
  SlamCounters counters() const override;
  const char* modeName() const override { return "edge"; }

  double finish_timeout_s = 30.0;

 private:
  void onSlice(MapSlice slice);

  std::unique_ptr<EdgeLink> link_;
  std::unique_ptr<EdgeKeyFrameSink> sink_;
  mutable std::mutex stats_mutex_;
  SampleStats slice_latency_ms_;
  SampleStats slice_apply_ms_;
  std::uint64_t slices_applied_ = 0;
  std::uint64_t loops_ = 0;
};

}  // namespace edgeslam
