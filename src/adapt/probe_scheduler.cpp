#include "adapt/probe_scheduler.h"

#include <algorithm>
#include <cmath>

namespace edgeslam {
namespace {

constexpr std::size_t kFramingBytes = 250;
constexpr std::size_t kSegmentHeaderBytes = 52;
constexpr std::size_t kSegmentPayload = 1400;

std::size_t segments(std::size_t bytes) {
  return std::max<std::size_t>(1, (bytes + kSegmentPayload - 1) / kSegmentPayload);
}

}  // namespace

std::size_t estimatedProbeWireBytes(std::size_t payload_bytes, std::size_t reply_bytes) {
  return payload_bytes + reply_bytes + kFramingBytes +
         kSegmentHeaderBytes * (segments(payload_bytes) + segments(reply_bytes));
}

ProbeScheduler::ProbeScheduler(ProbeSchedule schedule) : schedule_(schedule) {}

ProbeKind ProbeScheduler::next(double now_s) {
  const bool small_due = !next_small_s_ || now_s >= *next_small_s_;
  const bool sized_due = next_sized_s_ && now_s >= *next_sized_s_;
  // When both are due, the one due first goes first: with probes slower than the small interval
  // (a stalled link) the small probe is always due again and would starve the sized one.
  if (small_due && !(sized_due && *next_sized_s_ < *next_small_s_)) {
    // Keep the grid (probes stay `small_interval_s` apart on average); after a long pause, restart
    // it from now instead of firing a burst of overdue probes.
    double next = next_small_s_ ? *next_small_s_ + schedule_.small_interval_s : now_s;
    if (next <= now_s) next = now_s + schedule_.small_interval_s;
    next_small_s_ = next;
    if (!next_sized_s_) next_sized_s_ = now_s;
    return ProbeKind::kSmall;
  }
  if (sized_due) {
    const double interval = sized_sent_++ == 0
                                ? std::min(schedule_.small_interval_s, schedule_.sized_interval_s)
                                : schedule_.sized_interval_s;
    double next = *next_sized_s_ + interval;
    if (next <= now_s) next = now_s + schedule_.sized_interval_s;
    next_sized_s_ = next;
    return ProbeKind::kSized;
  }
  return ProbeKind::kNone;
}

std::size_t ProbeScheduler::sizedProbeBytes(std::optional<double> bandwidth_mbps) const {
  if (!bandwidth_mbps || *bandwidth_mbps <= 0.0) return schedule_.sized_min_bytes;
  const double bytes = *bandwidth_mbps * 1e6 / 8.0 * schedule_.sized_target_ms / 1e3;
  return std::clamp(static_cast<std::size_t>(std::ceil(bytes)), schedule_.sized_min_bytes,
                    schedule_.sized_max_bytes);
}

double ProbeScheduler::wireBytesPerSecond(std::optional<double> bandwidth_mbps) const {
  const double small = static_cast<double>(estimatedProbeWireBytes(schedule_.small_payload_bytes,
                                                                   schedule_.small_payload_bytes)) /
                       schedule_.small_interval_s;
  const double sized = static_cast<double>(estimatedProbeWireBytes(sizedProbeBytes(bandwidth_mbps),
                                                                   schedule_.small_payload_bytes)) /
                       schedule_.sized_interval_s;
  return small + sized;
}

}  // namespace edgeslam
