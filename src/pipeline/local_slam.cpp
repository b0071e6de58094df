#include "pipeline/local_slam.h"

namespace edgeslam {

LocalSlam::LocalSlam(const PinholeCamera& camera, SlamOptions options)
    : TrackingSlam(camera, std::move(options), 0) {
  mapper_ = std::make_unique<LocalMapper>(map_, camera_, options_.mapper);
  startTracking(mapper_.get());
  if (options_.threaded_mapping) mapper_->start();
}

LocalSlam::~LocalSlam() {
  mapper_->stop();
}

void LocalSlam::afterFrame() {
  if (!options_.threaded_mapping) mapper_->processAll();
}

void LocalSlam::finish() {
  mapper_->waitUntilIdle();
}

}  // namespace edgeslam
