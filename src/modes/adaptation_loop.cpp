#include "modes/adaptation_loop.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

using Clock = std::chrono::steady_clock;

AdaptationLoop::ProbeFunction probeThrough(EdgeClient& client) {
  return [&client](std::size_t payload_bytes, std::size_t reply_bytes,
                   std::chrono::milliseconds timeout) {
    return client.probe(payload_bytes, reply_bytes, timeout);
  };
}

std::string formatEstimate(std::optional<double> value, const char* unit) {
  return value ? fmt::format("{:.1f} {}", *value, unit) : std::string("-");
}

}  // namespace

AdaptationLoop::AdaptationLoop(EdgeClient& client, AdaptationLoopOptions options)
    : AdaptationLoop(probeThrough(client), options, [&client] { return client.connected(); }) {}

AdaptationLoop::AdaptationLoop(ProbeFunction probe, AdaptationLoopOptions options,
                               ReachabilityFunction edge_reachable)
    : options_(options),
      probe_(std::move(probe)),
      edge_reachable_(std::move(edge_reachable)),
      controller_(options.controller),
      scheduler_(options.schedule),
      estimator_(options.controller.estimator_window),
      message_bytes_(options.controller.message_bytes),
      current_(controller_.config()),
      current_row_(controller_.row()) {
  if (!probe_) throw std::invalid_argument("adaptation loop: no probe function");
  if (options_.probe_timeout.count() <= 0 || options_.poll_interval.count() <= 0) {
    throw std::invalid_argument(fmt::format(
        "adaptation loop: probe_timeout ({} ms) and poll_interval ({} ms) must be positive",
        options_.probe_timeout.count(), options_.poll_interval.count()));
  }
  if (!(options_.schedule.small_interval_s > 0.0) || !(options_.schedule.sized_interval_s > 0.0)) {
    throw std::invalid_argument("adaptation loop: probe intervals must be positive");
  }
}

AdaptationLoop::~AdaptationLoop() {
  stop();
}

void AdaptationLoop::start() {
  MutexLock lock(thread_mutex_);
  if (thread_.joinable()) return;
  {
    MutexLock wake_lock(wake_mutex_);
    if (stopping_) return;  // stopped before it ever ran
  }
  spdlog::info("adaptation {}: probing every {:g} s (latency) and {:g} s (bandwidth)",
               options_.adapt ? "on" : "off (probing only)", options_.schedule.small_interval_s,
               options_.schedule.sized_interval_s);
  thread_ = std::thread([this] { run(); });
}

void AdaptationLoop::stop() {
  MutexLock lock(thread_mutex_);
  {
    MutexLock wake_lock(wake_mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void AdaptationLoop::setMessageBytes(double bytes) {
  if (!(bytes >= 0.0) || !std::isfinite(bytes)) {
    throw std::invalid_argument(fmt::format("adaptation loop: message size {} bytes", bytes));
  }
  controller_.setMessageBytes(bytes);
  MutexLock lock(state_mutex_);
  message_bytes_ = bytes;
}

void AdaptationLoop::onFrame() {
  controller_.onFrame();
}

KeyframeConfig AdaptationLoop::current() const {
  MutexLock lock(state_mutex_);
  return current_;
}

std::size_t AdaptationLoop::row() const {
  MutexLock lock(state_mutex_);
  return current_row_;
}

NetworkEstimates AdaptationLoop::estimates() const {
  MutexLock lock(state_mutex_);
  NetworkEstimates out;
  out.latency_ms = estimator_.latencyMs();
  out.bandwidth_mbps = estimator_.bandwidthMbps();
  out.network_time_ms = estimator_.networkTimeMs(message_bytes_);
  out.message_bytes = message_bytes_;
  return out;
}

AdaptationLoopCounters AdaptationLoop::counters() const {
  AdaptationLoopCounters out;
  out.switches = controller_.switches();
  out.frames_per_config = controller_.framesPerConfig();
  MutexLock lock(state_mutex_);
  out.probe_bytes = probe_bytes_;
  out.probe_uplink_bytes = probe_uplink_bytes_;
  out.probe_downlink_bytes = probe_downlink_bytes_;
  out.latency_probes = latency_probes_;
  out.bandwidth_probes = bandwidth_probes_;
  out.failed_probes = failed_probes_;
  out.unreachable_probes = unreachable_probes_;
  return out;
}

void AdaptationLoop::run() {
  const auto origin = Clock::now();
  MutexLock lock(wake_mutex_);
  while (!stopping_) {
    lock.unlock();
    const double now_s = std::chrono::duration<double>(Clock::now() - origin).count();
    bool keep_probing = true;
    try {
      switch (scheduler_.next(now_s)) {
        case ProbeKind::kSmall:
          probeLatency();
          break;
        case ProbeKind::kSized:
          probeBandwidth();
          break;
        case ProbeKind::kNone:
          break;
      }
    } catch (const EdgeClientError& e) {
      spdlog::warn("adaptation: the edge refuses probes, keeping configuration {}: {}", row() + 1,
                   e.what());
      keep_probing = false;
    } catch (const std::exception& e) {
      spdlog::error("adaptation: probing stopped: {}", e.what());
      keep_probing = false;
    }
    lock.lock();
    if (!keep_probing) {
      lock.wait(wake_, [this]() REQUIRES(wake_mutex_) { return stopping_; });
      break;
    }
    lock.waitFor(wake_, options_.poll_interval,
                 [this]() REQUIRES(wake_mutex_) { return stopping_; });
  }
}

AdaptationLoop::ProbeOutcome AdaptationLoop::timedProbe(std::size_t payload_bytes,
                                                        std::size_t reply_bytes) {
  const auto start = Clock::now();
  const std::optional<ProbeResult> result =
      probe_(payload_bytes, reply_bytes, options_.probe_timeout);
  const double elapsed_ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  const std::size_t wire = estimatedProbeWireBytes(payload_bytes, reply_bytes);
  const bool unreachable = !result && edge_reachable_ && !edge_reachable_();
  MutexLock lock(state_mutex_);
  probe_bytes_ += wire;
  if (unreachable) {
    ++unreachable_probes_;
    spdlog::debug("adaptation: probe of {} B failed with the edge unreachable: no sample",
                  payload_bytes);
    return {elapsed_ms, false, true};
  }
  if (!result) {
    ++failed_probes_;
    const double timeout_ms =
        std::chrono::duration<double, std::milli>(options_.probe_timeout).count();
    spdlog::debug("adaptation: probe of {} B unanswered after {:.0f} ms", payload_bytes,
                  elapsed_ms);
    return {std::max(elapsed_ms, timeout_ms), false, false};
  }
  spdlog::debug("adaptation: probe of {} B answered in {:.2f} ms", payload_bytes,
                result->round_trip_ms);
  probe_uplink_bytes_ += result->sent_bytes;
  probe_downlink_bytes_ += result->received_bytes;
  return {result->round_trip_ms, true};
}

void AdaptationLoop::probeLatency() {
  const std::size_t payload = options_.schedule.small_payload_bytes;
  const ProbeOutcome outcome = timedProbe(payload, payload);
  if (outcome.unreachable) return;
  const double rtt_ms = outcome.elapsed_ms;
  {
    MutexLock lock(state_mutex_);
    ++latency_probes_;
    estimator_.addLatencyProbe(rtt_ms);
  }
  if (options_.adapt) {
    publishIfSwitched(
        controller_.onLatencyProbe(rtt_ms, estimatedProbeWireBytes(payload, payload)));
  } else {
    logWouldBeRow();
  }
}

void AdaptationLoop::probeBandwidth() {
  std::optional<double> bandwidth;
  {
    MutexLock lock(state_mutex_);
    bandwidth = estimator_.bandwidthMbps();
  }
  const std::size_t largest = options_.schedule.sized_max_bytes;
  const std::size_t reply = options_.schedule.small_payload_bytes;
  // A probe too fast to resolve is followed at once by one twice as large, up to the largest.
  for (std::size_t payload = scheduler_.sizedProbeBytes(bandwidth);;
       payload = std::min(largest, 2 * payload)) {
    const ProbeOutcome outcome = timedProbe(payload, reply);
    if (outcome.unreachable) return;
    double elapsed_ms = outcome.elapsed_ms;
    const bool at_largest = payload >= largest;
    bool resolved = true;
    {
      MutexLock lock(state_mutex_);
      if (!outcome.answered) {
        // The link moved fewer than `payload` bytes in the whole timeout, on top of its latency
        // (which may itself be made of timeouts): B <= payload / timeout.
        elapsed_ms += estimator_.latencyMs().value_or(0.0);
      }
      ++bandwidth_probes_;
      resolved = !estimator_.latencyMs() || estimator_.resolves(elapsed_ms);
      estimator_.addBandwidthProbe(payload, elapsed_ms, at_largest);
    }
    if (options_.adapt) {
      publishIfSwitched(controller_.onBandwidthProbe(
          payload, elapsed_ms, estimatedProbeWireBytes(payload, reply), at_largest));
    } else {
      logWouldBeRow();
    }
    if (resolved || at_largest) return;
    MutexLock wake_lock(wake_mutex_);
    if (stopping_) return;
  }
}

void AdaptationLoop::publishIfSwitched(bool switched) {
  if (!switched) return;
  const KeyframeConfig config = controller_.config();
  const std::size_t row = controller_.row();
  {
    MutexLock lock(state_mutex_);
    current_ = config;
    current_row_ = row;
  }
  version_.fetch_add(1, std::memory_order_acq_rel);
}

void AdaptationLoop::logWouldBeRow() {
  const NetworkEstimates now = estimates();
  if (!now.network_time_ms) return;
  const std::size_t row = adaptationRowFor(*now.network_time_ms);
  {
    MutexLock lock(state_mutex_);
    if (logged_row_ == row) return;
    logged_row_ = row;
  }
  spdlog::info("adaptation off: L {} B {} N {} would pick configuration {}",
               formatEstimate(now.latency_ms, "ms"), formatEstimate(now.bandwidth_mbps, "Mbit/s"),
               formatEstimate(now.network_time_ms, "ms"), row + 1);
}

}  // namespace edgeslam
