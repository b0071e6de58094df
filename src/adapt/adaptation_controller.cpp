#include "adapt/adaptation_controller.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {

AdaptationController::AdaptationController(AdaptationOptions options)
    : options_(options), estimator_(options.estimator_window), row_(options.initial_row) {
  if (options_.initial_row >= kAdaptationRows) {
    throw std::invalid_argument(fmt::format("initial adaptation row {} is not below {}",
                                            options_.initial_row, kAdaptationRows));
  }
  if (options_.confirm_count < 1) {
    throw std::invalid_argument(
        fmt::format("confirm_count {} must be at least 1", options_.confirm_count));
  }
  if (!(options_.message_bytes >= 0.0) || !(options_.margin_fraction >= 0.0) ||
      !(options_.min_margin_ms >= 0.0)) {
    throw std::invalid_argument("message_bytes and margins must be >= 0");
  }
  const std::size_t window = std::max<std::size_t>(1, options_.estimator_window);
  if (options_.first_estimate_latency_samples > window ||
      options_.first_estimate_bandwidth_samples > window) {
    throw std::invalid_argument(fmt::format(
        "first estimate on {} latency and {} bandwidth samples: more than the estimator window {}",
        options_.first_estimate_latency_samples, options_.first_estimate_bandwidth_samples,
        options_.estimator_window));
  }
}

bool AdaptationController::onLatencyProbe(double rtt_ms, std::size_t wire_bytes) {
  MutexLock lock(mutex_);
  probe_bytes_ += wire_bytes;
  estimator_.addLatencyProbe(rtt_ms);
  return reevaluateLocked();
}

bool AdaptationController::onBandwidthProbe(std::size_t payload_bytes, double elapsed_ms,
                                            std::size_t wire_bytes, bool largest) {
  MutexLock lock(mutex_);
  probe_bytes_ += wire_bytes;
  if (!estimator_.addBandwidthProbe(payload_bytes, elapsed_ms, largest)) return false;
  return reevaluateLocked();
}

void AdaptationController::setMessageBytes(double message_bytes) {
  if (!(message_bytes >= 0.0)) {
    throw std::invalid_argument(fmt::format("message size {} bytes is invalid", message_bytes));
  }
  MutexLock lock(mutex_);
  options_.message_bytes = message_bytes;
}

bool AdaptationController::observe(double n_ms) {
  MutexLock lock(mutex_);
  return observeLocked(n_ms);
}

bool AdaptationController::reevaluateLocked() {
  const auto n_ms = estimator_.networkTimeMs(options_.message_bytes);
  if (!n_ms) return false;
  if (!has_estimate_ &&
      (estimator_.latencySampleCount() < options_.first_estimate_latency_samples ||
       estimator_.bandwidthSampleCount() < options_.first_estimate_bandwidth_samples)) {
    last_n_ms_ = *n_ms;
    return false;
  }
  return observeLocked(*n_ms);
}

double AdaptationController::marginMs(double boundary_ms) const {
  return std::max(options_.min_margin_ms, options_.margin_fraction * boundary_ms);
}

bool AdaptationController::observeLocked(double n_ms) {
  if (std::isnan(n_ms)) throw std::invalid_argument("network time N is NaN");
  last_n_ms_ = n_ms;
  std::size_t target = row_;
  if (!has_estimate_) {
    has_estimate_ = true;
    target = adaptationRowFor(n_ms);
  } else {
    const AdaptationRow& current = adaptationTable()[row_];
    const bool below = row_ > 0 && n_ms <= current.n_low_ms - marginMs(current.n_low_ms);
    const bool above =
        row_ + 1 < kAdaptationRows && n_ms > current.n_high_ms + marginMs(current.n_high_ms);
    if (!below && !above) {
      outside_count_ = 0;
      return false;
    }
    if (++outside_count_ < options_.confirm_count) return false;
    target = adaptationRowFor(n_ms);
  }
  outside_count_ = 0;
  if (target == row_) return false;
  spdlog::info("adaptation: N = {:.1f} ms, configuration {} -> {} ({})", n_ms, row_ + 1, target + 1,
               adaptationTable()[target].config.describe());
  row_ = target;
  ++switches_;
  return true;
}

KeyframeConfig AdaptationController::config() const {
  MutexLock lock(mutex_);
  return adaptationTable()[row_].config;
}

std::size_t AdaptationController::row() const {
  MutexLock lock(mutex_);
  return row_;
}

std::optional<double> AdaptationController::lastNetworkTimeMs() const {
  MutexLock lock(mutex_);
  return last_n_ms_;
}

NetworkEstimator AdaptationController::estimator() const {
  MutexLock lock(mutex_);
  return estimator_;
}

void AdaptationController::onFrame() {
  MutexLock lock(mutex_);
  ++frames_[row_];
}

std::uint64_t AdaptationController::switches() const {
  MutexLock lock(mutex_);
  return switches_;
}

std::array<std::uint64_t, kAdaptationRows> AdaptationController::framesPerConfig() const {
  MutexLock lock(mutex_);
  return frames_;
}

std::uint64_t AdaptationController::probeBytes() const {
  MutexLock lock(mutex_);
  return probe_bytes_;
}

}  // namespace edgeslam
