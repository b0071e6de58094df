#pragma once
// Self-adaptation on the client (paper Sec. V): a background thread that probes the live channel
// to the edge (small probes for the latency L, sized probes for the bandwidth B, on the
// ProbeScheduler's timetable), feeds the AdaptationController with N = L + M/B, and publishes
// the Table I configuration the tracker should use. The frame loop only reads: version() is one
// atomic load, current() a short lock; nothing it calls waits for the network.
//
// With `adapt` off the loop still probes (L, B and N are still estimated, logged and reported)
// but the configuration never changes: the run keeps its own keyframe parameters.
#include <array>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <thread>

#include "adapt/adaptation_controller.h"
#include "adapt/keyframe_config.h"
#include "adapt/network_estimator.h"
#include "adapt/probe_scheduler.h"
#include "util/mutex.h"
#include "wire/edge_client.h"

namespace edgeslam {

struct AdaptationLoopOptions {
  bool adapt = true;  // false: probe and estimate, never switch
  ProbeSchedule schedule;
  // controller.initial_row is the configuration in effect until the first estimate (and for
  // good with adapt off): give the row the run starts with so frames_per_config is truthful.
  AdaptationOptions controller;
  // A probe not answered within this counts as a sample of this duration (a very slow link);
  // it also bounds how long stop() can wait for a probe in flight.
  std::chrono::milliseconds probe_timeout{1000};
  // How often the thread asks the scheduler whether a probe is due.
  std::chrono::milliseconds poll_interval{20};
};

// The latest estimates, for logs and metrics; empty until the first probe of each kind.
struct NetworkEstimates {
  std::optional<double> latency_ms;       // L: median RTT of the small probes
  std::optional<double> bandwidth_mbps;   // B: uplink, median of the sized probes
  std::optional<double> network_time_ms;  // N = L + M/B
  double message_bytes = 0.0;             // M used for N
};

struct AdaptationLoopCounters {
  std::uint64_t switches = 0;  // configuration changes (the first estimate's included); 0 when off
  std::array<std::uint64_t, kAdaptationRows> frames_per_config{};  // onFrame() per Table I row
  std::uint64_t probe_bytes = 0;           // estimated bytes on the wire (estimatedProbeWireBytes)
  std::uint64_t probe_uplink_bytes = 0;    // serialized request bytes (inside the client's
  std::uint64_t probe_downlink_bytes = 0;  // uplink/downlink counters: subtract for M)
  std::uint64_t latency_probes = 0;
  std::uint64_t bandwidth_probes = 0;
  std::uint64_t failed_probes = 0;  // timed out on a connected link: fed as probe_timeout samples
  // Failed while the edge was unreachable (server down or restarting, link gone): no sample.
  std::uint64_t unreachable_probes = 0;
};

class AdaptationLoop {
 public:
  // Sends `payload_bytes` up and asks for `reply_bytes` back; nullopt when not answered in time.
  // May throw EdgeClientError (the server refuses probes: probing stops, the config stays).
  using ProbeFunction = std::function<std::optional<ProbeResult>(
      std::size_t payload_bytes, std::size_t reply_bytes, std::chrono::milliseconds timeout)>;

  // Whether the edge can be reached now; asked after a probe failed.
  using ReachabilityFunction = std::function<bool()>;

  // Probes through `client`, which must outlive the loop (stop the loop before closing it).
  AdaptationLoop(EdgeClient& client, AdaptationLoopOptions options = {});
  // A probe that fails while `edge_reachable` says false is no sample: an outage (a server
  // restart, a dropped link) says nothing about the link the configuration is for, and taking
  // it as a 1 s round trip switched to the slowest row (fmin 40) for the outage and ~10 s after,
  // a third fewer keyframes. Without the function every failed probe is a sample.
  AdaptationLoop(ProbeFunction probe, AdaptationLoopOptions options = {},
                 ReachabilityFunction edge_reachable = {});
  ~AdaptationLoop();  // stop()
  AdaptationLoop(const AdaptationLoop&) = delete;
  AdaptationLoop& operator=(const AdaptationLoop&) = delete;

  // Starts the probing thread (once; later calls do nothing).
  void start();
  // Ends the thread: returns at once when idle, else after the probe in flight (at most
  // probe_timeout). Idempotent; the getters stay valid afterwards.
  void stop();

  // M: serialized bytes of one keyframe upload (e.g. the client's uplink bytes minus
  // probe_uplink_bytes, divided by the keyframes uploaded). Throws for a negative or NaN size.
  void setMessageBytes(double bytes);
  // Counts one processed frame under the configuration in effect (frames_per_config).
  void onFrame();

  // The configuration to apply, and a counter that changes with it (0 = the initial one).
  KeyframeConfig current() const;
  std::uint64_t version() const { return version_.load(std::memory_order_acquire); }
  std::size_t row() const;  // Table I row of current(), 0-based
  bool adapting() const { return options_.adapt; }

  NetworkEstimates estimates() const;
  AdaptationLoopCounters counters() const;

 private:
  void run();
  void probeLatency();
  void probeBandwidth();
  struct ProbeOutcome {
    double elapsed_ms = 0.0;  // at least probe_timeout when unanswered
    bool answered = false;
    bool unreachable = false;  // unanswered with the edge unreachable: not a sample
  };
  // Runs one probe and counts its bytes; EdgeClientError passes through.
  ProbeOutcome timedProbe(std::size_t payload_bytes, std::size_t reply_bytes);
  void publishIfSwitched(bool switched);
  void logWouldBeRow();

  AdaptationLoopOptions options_;
  ProbeFunction probe_;
  ReachabilityFunction edge_reachable_;
  AdaptationController controller_;
  ProbeScheduler scheduler_;

  mutable Mutex state_mutex_;  // guards what follows up to the counters
  NetworkEstimator estimator_
      GUARDED_BY(state_mutex_);  // mirrors the controller's, also fed with adapt off
  double message_bytes_ GUARDED_BY(state_mutex_);
  KeyframeConfig current_ GUARDED_BY(state_mutex_);
  std::size_t current_row_ GUARDED_BY(state_mutex_);
  std::optional<std::size_t> logged_row_ GUARDED_BY(state_mutex_);
  std::uint64_t probe_bytes_ GUARDED_BY(state_mutex_) = 0;
  std::uint64_t probe_uplink_bytes_ GUARDED_BY(state_mutex_) = 0;
  std::uint64_t probe_downlink_bytes_ GUARDED_BY(state_mutex_) = 0;
  std::uint64_t latency_probes_ GUARDED_BY(state_mutex_) = 0;
  std::uint64_t bandwidth_probes_ GUARDED_BY(state_mutex_) = 0;
  std::uint64_t failed_probes_ GUARDED_BY(state_mutex_) = 0;
  std::uint64_t unreachable_probes_ GUARDED_BY(state_mutex_) = 0;
  std::atomic<std::uint64_t> version_{0};

  Mutex thread_mutex_;  // start()/stop()
  Mutex wake_mutex_;
  std::condition_variable wake_;
  bool stopping_ GUARDED_BY(wake_mutex_) = false;
  std::thread thread_ GUARDED_BY(thread_mutex_);
};

}  // namespace edgeslam
