#pragma once
// Picks the Table I configuration from the network condition N = L + M/B, with hysteresis so that
// noise around a row boundary does not make the keyframe rules flap:
//  - the first estimate selects its row directly, once it rests on `first_estimate_latency_samples`
//    latency probes and `first_estimate_bandwidth_samples` sized probes (a median of one sample
//    would let a slow first probe, which also opens the connection or meets the edge busy with
//    the new map's first keyframes, pick the row, and the hysteresis then keeps it);
//  - afterwards the row changes only when N leaves the current row's interval by a margin
//    (max(min_margin_ms, margin_fraction * boundary)) for `confirm_count` consecutive estimates;
//    it then moves to the row that holds the latest N.
// Thread-safe: probes may be reported from a network thread while frames are counted elsewhere.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>

#include "adapt/keyframe_config.h"
#include "adapt/network_estimator.h"
#include "util/mutex.h"

namespace edgeslam {

struct AdaptationOptions {
  // M: bytes sent per keyframe (the paper: one 1280x720 frame, about 100 KB as JPEG).
  double message_bytes = 100e3;
  double margin_fraction = 0.1;
  double min_margin_ms = 1.0;
  int confirm_count = 3;
  std::size_t estimator_window = 5;
  std::size_t first_estimate_latency_samples = 3;    // at most estimator_window
  std::size_t first_estimate_bandwidth_samples = 2;  // at most estimator_window
  std::size_t initial_row = kDefaultAdaptationRow;   // in effect until the first estimate
};

class AdaptationController {
 public:
  explicit AdaptationController(AdaptationOptions options = {});

  // Probe results; each re-evaluates N once latency and bandwidth are both known. `wire_bytes`
  // is what the probe cost on the link (counted in probeBytes()). Return true on a switch.
  bool onLatencyProbe(double rtt_ms, std::size_t wire_bytes);
  // `largest`: as NetworkEstimator::addBandwidthProbe.
  bool onBandwidthProbe(std::size_t payload_bytes, double elapsed_ms, std::size_t wire_bytes,
                        bool largest = true);
  void setMessageBytes(double message_bytes);

  // Feeds one estimate of N (ms) directly; true when the configuration changed.
  bool observe(double n_ms);

  KeyframeConfig config() const;
  std::size_t row() const;
  std::optional<double> lastNetworkTimeMs() const;
  NetworkEstimator estimator() const;

  // Counts a frame processed under the configuration in effect.
  void onFrame();
  std::uint64_t switches() const;
  std::array<std::uint64_t, kAdaptationRows> framesPerConfig() const;
  std::uint64_t probeBytes() const;

 private:
  bool observeLocked(double n_ms) REQUIRES(mutex_);
  bool reevaluateLocked() REQUIRES(mutex_);
  double marginMs(double boundary_ms) const;

  AdaptationOptions options_;
  mutable Mutex mutex_;
  NetworkEstimator estimator_ GUARDED_BY(mutex_);
  std::size_t row_ GUARDED_BY(mutex_);
  bool has_estimate_ GUARDED_BY(mutex_) = false;
  int outside_count_ GUARDED_BY(mutex_) = 0;
  std::optional<double> last_n_ms_ GUARDED_BY(mutex_);
  std::uint64_t switches_ GUARDED_BY(mutex_) = 0;
  std::array<std::uint64_t, kAdaptationRows> frames_ GUARDED_BY(mutex_){};
  std::uint64_t probe_bytes_ GUARDED_BY(mutex_) = 0;
};

}  // namespace edgeslam
