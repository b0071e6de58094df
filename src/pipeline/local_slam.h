#pragma once
// The whole SLAM in one process (`--mode local`, the ORB-SLAM baseline): tracking on the caller's
// thread, local mapping on its own thread, loop closing on another (with a vocabulary), one
// shared map.
#include <memory>

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

 private:
  void afterFrame() override;

  std::unique_ptr<LocalMapper> mapper_;
  std::unique_ptr<LoopCloser> loop_closer_;
};

}  // namespace edgeslam
