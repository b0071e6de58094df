#include "linkem/link_settings.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <array>
#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

struct NamedProfile {
  std::string_view name;
  LinkSettings settings;
};

// Why these numbers: docs/links.md ("Profiles") gives the measurements they come from.
const std::array<NamedProfile, 5>& profiles() {
  static const std::array<NamedProfile, 5> table{{
      {"none", LinkSettings{}},
      {"wifi5", LinkSettings{.delay_up_ms = 1.5,
                             .delay_down_ms = 1.5,
                             .jitter_ms = 1.0,
                             .up_mbps = 200.0,
                             .down_mbps = 300.0,
                             .loss = 0.0005}},
      {"wifi24", LinkSettings{.delay_up_ms = 5.0,
                              .delay_down_ms = 5.0,
                              .jitter_ms = 4.0,
                              .up_mbps = 50.0,
                              .down_mbps = 60.0,
                              .loss = 0.002}},
      {"lte", LinkSettings{.delay_up_ms = 25.0,
                           .delay_down_ms = 20.0,
                           .jitter_ms = 10.0,
                           .up_mbps = 8.0,
                           .down_mbps = 25.0,
                           .loss = 0.005}},
      {"lte-congested", LinkSettings{.delay_up_ms = 50.0,
                                     .delay_down_ms = 40.0,
                                     .jitter_ms = 30.0,
                                     .up_mbps = 2.0,
                                     .down_mbps = 5.0,
                                     .loss = 0.01}},
  }};
  return table;
}

void requireNonNegative(double value, std::string_view field) {
  if (!std::isfinite(value) || value < 0.0) {
    throw std::invalid_argument(
        fmt::format("link setting {} = {} must be finite and >= 0", field, value));
  }
}

std::string rate(double mbps) {
  return mbps > 0.0 ? fmt::format("{:g} Mbit/s", mbps) : std::string("unlimited");
}

}  // namespace

std::string LinkSettings::describe() const {
  return fmt::format(
      "up {} delay {:g} ms, down {} delay {:g} ms, jitter {:g} ms, loss {:g}% per segment",
      rate(up_mbps), delay_up_ms, rate(down_mbps), delay_down_ms, jitter_ms, loss * 100.0);
}

void validate(const LinkSettings& s) {
  requireNonNegative(s.delay_up_ms, "delay_up_ms");
  requireNonNegative(s.delay_down_ms, "delay_down_ms");
  requireNonNegative(s.jitter_ms, "jitter_ms");
  requireNonNegative(s.up_mbps, "up_mbps");
  requireNonNegative(s.down_mbps, "down_mbps");
  requireNonNegative(s.loss, "loss");
  if (s.loss >= 1.0) {
    throw std::invalid_argument(fmt::format("link setting loss = {} must be below 1", s.loss));
  }
}

LinkSettings linkProfile(std::string_view name) {
  for (const auto& profile : profiles()) {
    if (profile.name == name) return profile.settings;
  }
  throw std::invalid_argument(fmt::format("unknown link profile '{}' (known: {})", name,
                                          fmt::join(linkProfileNames(), ", ")));
}

std::vector<std::string> linkProfileNames() {
  std::vector<std::string> names;
  for (const auto& profile : profiles()) names.emplace_back(profile.name);
  return names;
}

}  // namespace edgeslam
