#include "modes/paced_keyframe_sink.h"

namespace edgeslam {

PacedKeyFrameSink::PacedKeyFrameSink(KeyFrameSink& inner, std::function<void()> wait_until_idle)
    : inner_(inner), wait_until_idle_(std::move(wait_until_idle)) {}

void PacedKeyFrameSink::insertKeyFrame(KeyFrame* keyframe) {
  if (wait_until_idle_) waitFor(wait_until_idle_);
  inner_.insertKeyFrame(keyframe);
}

void PacedKeyFrameSink::waitFor(const std::function<void()>& wait) {
  Stopwatch waited;
  wait();
  const double ms = waited.elapsedMs();
  MutexLock lock(mutex_);
  waits_.add(ms);
}

bool PacedKeyFrameSink::acceptsKeyFrames() const {
  const bool accepts = inner_.acceptsKeyFrames();
  if (!accepts) ++busy_refusals_;
  return accepts;
}

double PacedKeyFrameSink::waitTotalMs() const {
  MutexLock lock(mutex_);
  return waits_.totalMs();
}

BackendPacing PacedKeyFrameSink::pacing() const {
  MutexLock lock(mutex_);
  return waits_.pacing(busy_refusals_.load());
}

}  // namespace edgeslam
