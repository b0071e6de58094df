#pragma once
// Stopping a running Ceres solve from outside: a cancel flag (e.g. set by the mapping thread when a
// new keyframe arrives) and an optional per-iteration hook, both checked at the end of each
// iteration.
#include <ceres/iteration_callback.h>

#include <atomic>
#include <functional>
#include <utility>

namespace edgeslam {

// Called after every solver iteration with the running iteration count of the whole run.
using IterationHook = std::function<void(int iteration)>;

class SolverControlCallback final : public ceres::IterationCallback {
 public:
  SolverControlCallback(const std::atomic<bool>* cancel, IterationHook hook, int first_iteration)
      : cancel_(cancel), hook_(std::move(hook)), iteration_(first_iteration) {}

  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    if (summary.iteration > 0) ++iteration_;  // iteration 0 is the initial evaluation
    if (hook_ && summary.iteration > 0) hook_(iteration_);
    if (cancelled()) {
      cancelled_seen_ = true;
      return ceres::SOLVER_TERMINATE_SUCCESSFULLY;
    }
    return ceres::SOLVER_CONTINUE;
  }

  bool cancelled() const { return cancel_ != nullptr && cancel_->load(std::memory_order_relaxed); }
  bool cancelledDuringSolve() const { return cancelled_seen_; }
  int iterations() const { return iteration_; }

 private:
  const std::atomic<bool>* cancel_;
  IterationHook hook_;
  int iteration_;
  bool cancelled_seen_ = false;
};

}  // namespace edgeslam
