#pragma once
// The whole SLAM in one process (`--mode local`, the ORB-SLAM baseline): tracking on the caller's
// thread feeding the mapping back end (mapping/mapping_backend.h: local mapping, loop closing with
// a vocabulary, keyframe segmentation with semantic culling) over one shared map.
#include <memory>

#include "mapping/mapping_backend.h"
#include "modes/slam_system.h"

namespace edgeslam {

class LocalSlam : public TrackingSlam {
 public:
  LocalSlam(const PinholeCamera& camera, SlamOptions options);
  ~LocalSlam() override;

  void finish() override;
  const char* modeName() const override { return "local"; }
  const MappingBackend& backend() const { return *backend_; }
  SlamCounters counters() const override;
  // nullptr without a vocabulary or with loop closing off.
  const LoopCloser* loopCloser() const { return backend_->loopCloser(); }
  // Why a back-end worker (mapping, loop closing, segmentation) ended with an exception; the
  // next frame then throws it.
  std::optional<std::string> failure() const;
  std::optional<MapIntrinsicsRefinement> intrinsicsRefinement() const override {
    return intrinsics_refinement_;
  }

 private:
  void afterFrame() override;
  void beforeCulling(std::size_t frame_index, const cv::Mat& image) override;
  void afterTracking(const TrackResult& result, std::size_t frame_index,
                     const cv::Mat& image) override;
  // keyframe kInvalidId: a frame before the map exists (its mask serves tracking only).
  void submitSegmentation(KeyFrameId keyframe, std::size_t frame_index, const cv::Mat& image);
  void segmentAndWaitWhenFast(KeyFrameId keyframe, std::size_t frame_index, const cv::Mat& image);
  void refineIntrinsicsOfTheMap();

  std::unique_ptr<MappingBackend> backend_;
  std::optional<MapIntrinsicsRefinement> intrinsics_refinement_;
  std::size_t next_frame_to_segment_before_the_map_ = 0;
  bool first_frame_mask_awaited_ = false;
};

}  // namespace edgeslam
