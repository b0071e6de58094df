#pragma once
// When to probe the link, and what probing costs. Every `small_interval_s` a small echo probe
// (latency); every `sized_interval_s` a sized probe (bandwidth; the second one already a small
// interval after the first, as the first estimate waits for two) big enough that its transfer time
// stands out of the RTT noise: about `sized_target_ms` at the current bandwidth estimate, clamped
// to [sized_min_bytes, sized_max_bytes]. Costs are in docs/links.md ("Probe costs").
#include <cstddef>
#include <optional>

namespace edgeslam {

enum class ProbeKind { kNone, kSmall, kSized };

struct ProbeSchedule {
  double small_interval_s = 1.0;
  double sized_interval_s = 5.0;
  std::size_t small_payload_bytes = 32;  // each way
  std::size_t sized_min_bytes = 4 * 1024;
  std::size_t sized_max_bytes = 64 * 1024;
  double sized_target_ms = 5.0;
};

// Estimated bytes on the wire for one probe round trip carrying `payload_bytes` upstream and a
// small reply: gRPC/HTTP2 framing (~250 B for request headers, reply headers and trailers once
// HPACK has the names) plus 52 B of TCP/IP headers (with timestamps) per ~1400-byte segment.
std::size_t estimatedProbeWireBytes(std::size_t payload_bytes, std::size_t reply_bytes);

class ProbeScheduler {
 public:
  explicit ProbeScheduler(ProbeSchedule schedule = {});

  // The probe due at `now_s` (any monotonic origin), marked as sent; kNone when nothing is due.
  // The first call returns kSmall, the next one kSized: a bandwidth probe needs a latency first.
  // The second sized probe is due `small_interval_s` after the first, later ones every
  // `sized_interval_s`.
  ProbeKind next(double now_s);
  // Payload of the next sized probe for the current bandwidth estimate (Mbit/s).
  std::size_t sizedProbeBytes(std::optional<double> bandwidth_mbps) const;
  // Steady-state cost in bytes per second on the wire at the given bandwidth estimate.
  double wireBytesPerSecond(std::optional<double> bandwidth_mbps) const;

  const ProbeSchedule& schedule() const { return schedule_; }

 private:
  ProbeSchedule schedule_;
  std::optional<double> next_small_s_;
  std::optional<double> next_sized_s_;
  int sized_sent_ = 0;
};

}  // namespace edgeslam
