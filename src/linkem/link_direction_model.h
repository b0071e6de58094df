#pragma once
// When each byte read on one side of the emulated link is handed to the other side. Pure timing,
// no sockets, so the model is testable on its own. The model (docs/links.md, "Emulator model"):
//  - bytes are cut into segments of at most kSegmentBytes (a typical TCP MSS);
//  - serialisation: a segment occupies the bottleneck for bytes * 8 / rate; segments queue behind
//    each other (a FIFO bottleneck, equivalent to a token bucket with a one-segment bucket);
//  - propagation: each segment then takes the one-way delay plus a jitter drawn uniformly in
//    [0, jitter];
//  - loss as TCP feels it: with probability `loss` a segment is lost and arrives late by the
//    retransmission time: one RTT when at least three segments follow it in the same burst (fast
//    retransmit after three duplicate ACKs), otherwise a tail-loss probe timeout of
//    max(2 RTT, 10 ms); the retransmission occupies the bottleneck once more;
//  - TCP delivers in order: no segment is delivered before the one in front of it (jitter and
//    loss therefore delay what follows: head-of-line blocking).
// Not modelled: congestion-window reaction to loss, slow start, the connection handshake.
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace edgeslam {

using LinkClock = std::chrono::steady_clock;

struct LinkDirectionParams {
  double delay_ms = 0.0;
  double jitter_ms = 0.0;
  double mbps = 0.0;  // 0 = unlimited
  double loss = 0.0;
  double rtt_ms = 0.0;  // round trip of the whole link, for the retransmission penalty
};

struct ScheduledSegment {
  std::size_t bytes = 0;
  LinkClock::time_point deliver_at;
  bool lost = false;  // delivered late after an emulated retransmission
};

class LinkDirectionModel {
 public:
  static constexpr std::size_t kSegmentBytes = 1400;

  explicit LinkDirectionModel(std::uint64_t seed) : random_(seed) {}

  // Schedules a burst of `bytes` that became available at `now`.
  std::vector<ScheduledSegment> schedule(std::size_t bytes, LinkClock::time_point now,
                                         const LinkDirectionParams& params);

  // When the bottleneck has sent everything scheduled so far.
  LinkClock::time_point linkFreeAt() const { return link_free_at_; }
  LinkClock::time_point lastDelivery() const { return last_delivery_; }

 private:
  std::mt19937_64 random_;
  LinkClock::time_point link_free_at_{};
  LinkClock::time_point last_delivery_{};
};

}  // namespace edgeslam
