#pragma once
// Parameters of an emulated wireless link between a client and the edge, and the named profiles
// (wifi5, wifi24, lte, lte-congested; sources in docs/links.md). "up" is client -> target.
#include <string>
#include <string_view>
#include <vector>

namespace edgeslam {

struct LinkSettings {
  double delay_up_ms = 0.0;    // one-way propagation + queueing delay, client -> target
  double delay_down_ms = 0.0;  // target -> client
  double jitter_ms = 0.0;      // extra delay per segment, uniform in [0, jitter_ms]
  double up_mbps = 0.0;        // bottleneck rate client -> target; 0 = unlimited
  double down_mbps = 0.0;      // target -> client; 0 = unlimited
  double loss = 0.0;           // probability that a ~1400-byte segment is lost (TCP retransmits)

  // Round-trip time of a small message without queueing (delays plus mean jitter each way).
  double baseRttMs() const { return delay_up_ms + delay_down_ms + jitter_ms; }
  std::string describe() const;
};

// Throws std::invalid_argument naming the offending field when a value is negative, not finite,
// or the loss is outside [0, 1).
void validate(const LinkSettings& settings);

// The named profiles; throws std::invalid_argument listing the known names for an unknown one.
LinkSettings linkProfile(std::string_view name);
std::vector<std::string> linkProfileNames();

}  // namespace edgeslam
