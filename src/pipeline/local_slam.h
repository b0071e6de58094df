#pragma once
// The whole SLAM in one process (`--mode local`, the ORB-SLAM baseline): tracking on the caller's
// thread, local mapping on its own thread, one shared map.
#include <memory>

#include "edge/local_mapper.h"
#include "pipeline/slam_system.h"

namespace edgeslam {

class LocalSlam : public TrackingSlam {
 public:
  LocalSlam(const PinholeCamera& camera, SlamOptions options);
  ~LocalSlam() override;

  void finish() override;
  const char* modeName() const override { return "local"; }
  const LocalMapper& mapper() const { return *mapper_; }

 private:
  void afterFrame() override;

  std::unique_ptr<LocalMapper> mapper_;
};

}  // namespace edgeslam
