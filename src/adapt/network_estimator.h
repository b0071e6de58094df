#pragma once
// Latency L and bandwidth B of the link to the edge from probe results, and the network
// condition N = L + M/B of paper Eq. (2).
//  - L: round-trip time of small echo probes (a few tens of bytes each way);
//  - B: a sized probe sends `bytes` and waits for a small reply, taking RTT + bytes/B, so
//       B = bytes / (elapsed - L), with L the current latency estimate.
// Both are the median of the last `window` samples: one outlier (a retransmission, a scheduler
// hiccup) cannot move a median of 5, and a lasting change shows after 3 samples.
// A sized probe that came back no later than the latency estimate says the link moved its bytes
// faster than the probe can resolve. The caller then sends a larger one at once; a probe of the
// largest size that still does not resolve counts as a sample at the resolution bound (the fastest
// B it could show). Dropping such probes for good kept only the ones a busy edge or a starved
// client had delayed, and on a fast link their median alone made B look like a few Mbit/s (a
// loopback link at 6.6 Mbit/s, Table I's last row for a whole KITTI run); counting every small
// one at the bound made a jittery link look far faster than it is (wifi24: 393 for 50 Mbit/s).
#include <cstddef>
#include <deque>
#include <optional>

namespace edgeslam {

// N = L + M/B in ms; B in Mbit/s (0 or less: an unusable link, N = +inf).
double networkTimeMs(double latency_ms, double bandwidth_mbps, double message_bytes);

class NetworkEstimator {
 public:
  explicit NetworkEstimator(std::size_t window = 5);

  // Throws std::invalid_argument for a negative or non-finite RTT.
  void addLatencyProbe(double rtt_ms);
  // Whether a sized probe answered in `elapsed_ms` shows a transfer time above the resolution
  // (false until a latency estimate exists).
  bool resolves(double elapsed_ms) const;
  // `bytes` sent and acknowledged in `elapsed_ms`; `largest`: no larger probe will be sent.
  // Returns whether it became a sample: not until a latency estimate exists, not for an empty
  // probe, and not for one too fast to resolve unless it is the largest.
  bool addBandwidthProbe(std::size_t bytes, double elapsed_ms, bool largest = true);

  std::optional<double> latencyMs() const;
  std::size_t latencySampleCount() const { return latency_samples_.size(); }
  std::optional<double> bandwidthMbps() const;
  std::size_t bandwidthSampleCount() const { return bandwidth_samples_.size(); }
  // N for a message of `message_bytes`, once both estimates exist.
  std::optional<double> networkTimeMs(double message_bytes) const;

 private:
  static void push(std::deque<double>& samples, double value, std::size_t window);
  static double median(const std::deque<double>& samples);

  std::size_t window_;
  std::deque<double> latency_samples_;
  std::deque<double> bandwidth_samples_;
};

}  // namespace edgeslam
