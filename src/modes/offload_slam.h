#pragma once
// `--mode offload`, the paper's Mask-SLAM baseline: the client does no SLAM work; it encodes every
// frame, sends it to the edge and waits for the pose. What the split is measured against.
#include <memory>
#include <vector>

#include "modes/slam_system.h"
#include "wire/edge_client.h"

namespace edgeslam {

struct OffloadOptions {
  int jpeg_quality = 90;
};

class OffloadSlam : public SlamSystem {
 public:
  OffloadSlam(Sensor sensor, std::unique_ptr<EdgeClient> client, OffloadOptions options = {});
  ~OffloadSlam() override;

  TrackResult process(std::size_t frame_index, double timestamp, const cv::Mat& gray,
                      const cv::Mat& depth, const cv::Mat& color = cv::Mat()) override;
  void finish() override {}
  SlamCounters counters() const override;
  LinkTraffic linkTraffic() const override;
  const char* modeName() const override { return "offload"; }

  Trajectory trajectoryAtFrameTime() const override { return poses_; }
  // The edge keeps the refined poses; the client only ever learns the per-frame answers.
  Trajectory trajectoryFinal() const override { return poses_; }
  Trajectory keyframeTrajectory() const override { return {}; }
  std::size_t keyFrameCount() const override { return 0; }
  std::size_t mapPointCount() const override { return 0; }
  std::size_t relocalizations() const override { return 0; }
  std::size_t mapResets() const override { return 0; }

 private:
  Sensor sensor_;
  std::unique_ptr<EdgeClient> client_;
  OffloadOptions options_;
  Trajectory poses_;
  std::vector<int> encode_params_;
  SampleStats server_ms_;
  BackendWaits backend_waits_;  // the edge's, reported with each pose (frames fed back to back)
};

}  // namespace edgeslam
