#pragma once
// metrics.json's "initialization" and "lost_frames" blocks: why a run had no map or no pose.
#include <nlohmann/json.hpp>
#include <string>

#include "client/tracking_diagnostics.h"

namespace edgeslam {

nlohmann::json initializationJson(const TrackingDiagnostics& d);
nlohmann::json lostFramesJson(const TrackingDiagnostics& d);
// "low_parallax 35, too_few_features 3" (most frequent first; "" when nothing was refused).
std::string refusalSummary(const TrackingDiagnostics& d);

}  // namespace edgeslam
