#include "adapt/network_estimator.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

namespace edgeslam {
namespace {

// A transfer time shorter than this is below the clock's and the scheduler's resolution: the
// probe was too small to show the link's B, only that B is at least bytes / kMinTransferMs.
constexpr double kMinTransferMs = 0.05;

}  // namespace

double networkTimeMs(double latency_ms, double bandwidth_mbps, double message_bytes) {
  if (bandwidth_mbps <= 0.0) return std::numeric_limits<double>::infinity();
  // bytes * 8 bit / (Mbit/s * 1e6) s = bytes * 8 / (Mbit/s * 1e3) ms
  return latency_ms + message_bytes * 8.0 / (bandwidth_mbps * 1e3);
}

NetworkEstimator::NetworkEstimator(std::size_t window)
    : window_(std::max<std::size_t>(1, window)) {}

void NetworkEstimator::addLatencyProbe(double rtt_ms) {
  if (!std::isfinite(rtt_ms) || rtt_ms < 0.0) {
    throw std::invalid_argument(fmt::format("probe RTT {} ms is not a valid duration", rtt_ms));
  }
  push(latency_samples_, rtt_ms, window_);
}

bool NetworkEstimator::resolves(double elapsed_ms) const {
  const auto latency = latencyMs();
  return latency && elapsed_ms - *latency >= kMinTransferMs;
}

bool NetworkEstimator::addBandwidthProbe(std::size_t bytes, double elapsed_ms, bool largest) {
  if (!std::isfinite(elapsed_ms) || elapsed_ms < 0.0) {
    throw std::invalid_argument(
        fmt::format("sized probe time {} ms is not a valid duration", elapsed_ms));
  }
  const auto latency = latencyMs();
  if (!latency || bytes == 0) return false;
  if (!largest && !resolves(elapsed_ms)) return false;
  const double transfer_ms = std::max(kMinTransferMs, elapsed_ms - *latency);
  push(bandwidth_samples_, static_cast<double>(bytes) * 8.0 / (transfer_ms * 1e3), window_);
  return true;
}

std::optional<double> NetworkEstimator::latencyMs() const {
  if (latency_samples_.empty()) return std::nullopt;
  return median(latency_samples_);
}

std::optional<double> NetworkEstimator::bandwidthMbps() const {
  if (bandwidth_samples_.empty()) return std::nullopt;
  return median(bandwidth_samples_);
}

std::optional<double> NetworkEstimator::networkTimeMs(double message_bytes) const {
  const auto latency = latencyMs();
  const auto bandwidth = bandwidthMbps();
  if (!latency || !bandwidth) return std::nullopt;
  return edgeslam::networkTimeMs(*latency, *bandwidth, message_bytes);
}

void NetworkEstimator::push(std::deque<double>& samples, double value, std::size_t window) {
  samples.push_back(value);
  while (samples.size() > window) samples.pop_front();
}

double NetworkEstimator::median(const std::deque<double>& samples) {
  std::vector<double> sorted(samples.begin(), samples.end());
  std::sort(sorted.begin(), sorted.end());
  const std::size_t mid = sorted.size() / 2;
  return sorted.size() % 2 == 1 ? sorted[mid] : 0.5 * (sorted[mid - 1] + sorted[mid]);
}

}  // namespace edgeslam
