#pragma once
// The whole SLAM in one process (`--mode local`, the ORB-SLAM baseline): tracking on the caller's
// thread, local mapping on its own thread, loop closing on another (with a vocabulary), one
// shared map; with semantic culling, keyframes are segmented on a thread of their own too.
#include <atomic>
#include <memory>

#include "edge/keyframe_segmentation.h"
#include "edge/local_mapper.h"
#include "edge/loop_closer.h"
#include "pipeline/slam_system.h"

namespace edgeslam {

class LocalSlam : public TrackingSlam {
 public:
  LocalSlam(const PinholeCamera& camera, SlamOptions options);
  ~LocalSlam() override;

  void finish() override;
  const char* modeName() const override { return "local"; }
  const LocalMapper& mapper() const { return *mapper_; }
  SlamCounters counters() const override;
  // nullptr without a vocabulary or with loop closing off.
  const LoopCloser* loopCloser() const { return loop_closer_.get(); }
  // Why a back-end worker (mapping, loop closing, segmentation) ended with an exception; the
  // next frame then throws it.
  std::optional<std::string> failure() const;
  std::optional<MapIntrinsicsRefinement> intrinsicsRefinement() const override {
    return intrinsics_refinement_;
  }

 private:
  void afterFrame() override;
  void afterTracking(const TrackResult& result, std::size_t frame_index,
                     const cv::Mat& image) override;
  void onSegmented(KeyFrameSegmentationResult result);
  void refineIntrinsicsOfTheMap();

  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<LoopCloser> loop_closer_;
  std::unique_ptr<KeyFrameSegmentationWorker> segmentation_;
  std::atomic<std::uint64_t> movable_points_erased_{0};
  std::optional<MapIntrinsicsRefinement> intrinsics_refinement_;
};

}  // namespace edgeslam
