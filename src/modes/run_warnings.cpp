#include "modes/run_warnings.h"

#include <fmt/format.h>

#include <algorithm>

namespace edgeslam {

std::vector<std::string> runWarnings(const RunHealth& h, const RunWarningThresholds& t) {
  std::vector<std::string> out;
  const auto fraction = [](double part, double whole) { return whole > 0.0 ? part / whole : 0.0; };
  if (h.frames_dropped_late > 0) {
    out.push_back(fmt::format(
        "{} of {} frames skipped late: the client fell behind the camera and took the newest "
        "frame (--fast waits instead)",
        h.frames_dropped_late, h.frames));
  }
  const std::size_t processed =
      h.frames - std::min(h.frames, h.frames_dropped_late + h.frames_out_of_order);
  if (fraction(static_cast<double>(h.lost), static_cast<double>(processed)) > t.max_lost_fraction) {
    out.push_back(
        fmt::format("tracking lost on {} of {} frames ({:.0f} %)", h.lost, processed,
                    100.0 * fraction(static_cast<double>(h.lost), static_cast<double>(processed))));
  }
  if (fraction(static_cast<double>(h.backend_busy_refusals), static_cast<double>(h.tracked)) >
      t.max_busy_fraction) {
    out.push_back(fmt::format(
        "keyframe backlog: the back end could take no keyframe on {} of {} tracked frames",
        h.backend_busy_refusals, h.tracked));
  }
  if (fraction(h.backend_wait_ms, h.wall_ms) > t.max_wait_fraction) {
    out.push_back(fmt::format(
        "tracking waited {:.1f} s of {:.1f} s for the back end: the run is bound by mapping on "
        "this machine (the map is a camera-paced run's; --realtime here would drop frames)",
        h.backend_wait_ms / 1000.0, h.wall_ms / 1000.0));
  }
  if (h.frames_out_of_order > 0) {
    out.push_back(fmt::format(
        "{} of {} frames skipped: their timestamp repeated or went back (duplicated or out of "
        "order frames)",
        h.frames_out_of_order, h.frames));
  }
  if (!h.map_built) {
    out.push_back(fmt::format("no map was built in {} frames: initialisation refused ({})",
                              processed, h.refusals.empty() ? "no usable frame" : h.refusals));
  } else if (fraction(static_cast<double>(h.frames_without_map), static_cast<double>(processed)) >
             t.max_lost_fraction) {
    out.push_back(fmt::format("no map on {} of {} frames: initialisation refused ({})",
                              h.frames_without_map, processed,
                              h.refusals.empty() ? "no usable frame" : h.refusals));
  }
  if (h.maps_unmerged > 0) {
    out.push_back(fmt::format(
        "{} map(s) started after tracking was lost for good never met the first again: the "
        "poses tracked in them are in a frame of their own",
        h.maps_unmerged));
  }
  if (h.monocular && h.keyframe_depth_ratio > 0.0 &&
      (h.keyframe_depth_ratio > t.max_depth_ratio ||
       h.keyframe_depth_ratio < 1.0 / t.max_depth_ratio)) {
    out.push_back(fmt::format(
        "scale drift suspected: the last keyframes see the scene at {:.2f}x the depth of the first",
        h.keyframe_depth_ratio));
  }
  return out;
}

}  // namespace edgeslam
