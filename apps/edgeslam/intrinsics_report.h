#pragma once
// What `run` reports of the end-of-run intrinsics refinement besides its summary line
// (describe(), map_optimization.h): the metrics.json entry, and the refined camera file a later
// run can start from (--camera).
#include <filesystem>
#include <nlohmann/json.hpp>

#include "optimize/map_optimization.h"

namespace edgeslam::cli {

nlohmann::json intrinsicsRefinementJson(const MapIntrinsicsRefinement& refinement);
// Writes `camera_refined.yaml` into out_dir when the refinement was adopted; returns its path, or
// an empty path when nothing was written.
std::filesystem::path writeRefinedCamera(const std::filesystem::path& out_dir,
                                         const MapIntrinsicsRefinement& refinement);

}  // namespace edgeslam::cli
