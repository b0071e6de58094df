#include "linkem/link_direction_model.h"

#include <algorithm>

namespace edgeslam {
namespace {

LinkClock::duration fromMs(double ms) {
  return std::chrono::duration_cast<LinkClock::duration>(
      std::chrono::duration<double, std::milli>(ms));
}

}  // namespace

std::vector<ScheduledSegment> LinkDirectionModel::schedule(std::size_t bytes,
                                                           LinkClock::time_point now,
                                                           const LinkDirectionParams& params) {
  std::vector<ScheduledSegment> segments;
  const std::size_t count = (bytes + kSegmentBytes - 1) / kSegmentBytes;
  segments.reserve(count);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t i = 0; i < count; ++i) {
    ScheduledSegment segment;
    segment.bytes = std::min(kSegmentBytes, bytes - i * kSegmentBytes);
    const LinkClock::duration serialisation =
        params.mbps > 0.0 ? fromMs(static_cast<double>(segment.bytes) * 8.0 / (params.mbps * 1e3))
                          : LinkClock::duration::zero();
    link_free_at_ = std::max(link_free_at_, now) + serialisation;
    double extra_ms = params.jitter_ms > 0.0 ? unit(random_) * params.jitter_ms : 0.0;
    if (params.loss > 0.0 && unit(random_) < params.loss) {
      segment.lost = true;
      const bool fast_retransmit = count - i - 1 >= 3;
      extra_ms += fast_retransmit ? params.rtt_ms : std::max(2.0 * params.rtt_ms, 10.0);
      link_free_at_ += serialisation;  // the retransmitted copy
    }
    segment.deliver_at =
        std::max(last_delivery_, link_free_at_ + fromMs(params.delay_ms + extra_ms));
    last_delivery_ = segment.deliver_at;
    segments.push_back(segment);
  }
  return segments;
}

}  // namespace edgeslam
