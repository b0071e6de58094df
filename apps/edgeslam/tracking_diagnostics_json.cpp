#include "tracking_diagnostics_json.h"

#include <fmt/format.h>

#include <algorithm>
#include <utility>
#include <vector>

namespace edgeslam {

nlohmann::json initializationJson(const TrackingDiagnostics& d) {
  nlohmann::json refused = nlohmann::json::object();
  std::size_t total = 0;
  for (std::size_t i = 0; i < d.refusals.size(); ++i) {
    refused[toString(static_cast<InitRefusal>(i))] = d.refusals[i];
    total += d.refusals[i];
  }
  return {{"map_built", d.initialized_at_frame.has_value()},
          {"at_frame", d.initialized_at_frame ? nlohmann::json(*d.initialized_at_frame)
                                              : nlohmann::json(nullptr)},
          {"frames_without_map", d.frames_without_map},
          {"maps_built", d.initializations},
          {"refusals", total},
          {"refused", refused},
          {"last_refusal", d.last_refusal}};
}

nlohmann::json lostFramesJson(const TrackingDiagnostics& d) {
  nlohmann::json out = nlohmann::json::object();
  for (std::size_t i = 0; i < d.lost.size(); ++i) {
    out[toString(static_cast<LostCause>(i))] = d.lost[i];
  }
  return out;
}

std::string refusalSummary(const TrackingDiagnostics& d) {
  std::vector<std::pair<std::size_t, InitRefusal>> counts;
  for (std::size_t i = 0; i < d.refusals.size(); ++i) {
    if (d.refusals[i] > 0) counts.emplace_back(d.refusals[i], static_cast<InitRefusal>(i));
  }
  std::stable_sort(counts.begin(), counts.end(),
                   [](const auto& a, const auto& b) { return a.first > b.first; });
  std::string out;
  for (const auto& [count, refusal] : counts) {
    if (!out.empty()) out += ", ";
    out += fmt::format("{} {}", toString(refusal), count);
  }
  return out;
}

}  // namespace edgeslam
