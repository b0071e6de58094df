#include "pipeline/local_slam.h"

namespace edgeslam {

LocalSlam::LocalSlam(const PinholeCamera& camera, SlamOptions options)
    : TrackingSlam(camera, std::move(options), 0) {
  mapper_ = std::make_unique<LocalMapper>(map_, camera_, options_.mapper);
  if (options_.vocabulary != nullptr && options_.loop_closing) {
    LoopCloserOptions loop = options_.loop_closer;
    const LoopCloserOptions for_sensor = loopCloserOptionsFor(options_.sensor);
    loop.verifier.fix_scale = for_sensor.verifier.fix_scale;
    loop.correction.fix_scale = for_sensor.correction.fix_scale;
    loop.threaded = options_.threaded_mapping;
    loop_closer_ =
        std::make_unique<LoopCloser>(map_, camera_, options_.vocabulary, loop, mapper_.get());
    mapper_->setKeyFrameMappedCallback([this](KeyFrame* kf) { loop_closer_->insertKeyFrame(kf); });
    loop_closer_->start();
  }
  startTracking(mapper_.get());
  if (options_.threaded_mapping) mapper_->start();
}

LocalSlam::~LocalSlam() {
  if (loop_closer_) loop_closer_->stop();
  mapper_->stop();
}

void LocalSlam::afterFrame() {
  if (!options_.threaded_mapping) {
    mapper_->processAll();
    if (loop_closer_) loop_closer_->processAll();
  }
}

void LocalSlam::finish() {
  mapper_->waitUntilIdle();
  if (loop_closer_) loop_closer_->waitUntilIdle();
}

SlamCounters LocalSlam::counters() const {
  SlamCounters out;
  if (loop_closer_) out.loops = loop_closer_->loops();
  return out;
}

}  // namespace edgeslam
