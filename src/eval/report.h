#pragma once
// Human-readable tables and JSON objects (keys carry their unit: _m, _deg, _percent) of results.
#include <nlohmann/json.hpp>
#include <string>

#include "eval/ate.h"
#include "eval/kitti_metric.h"
#include "eval/rpe.h"

namespace edgeslam {

// {"metric":"ate","rmse_m","mean_m","median_m","std_m","min_m","max_m","pairs","scale","align",
//  "alignment":{"scale","rotation_xyzw","translation_m"}}
nlohmann::json toJson(const AteResult& result);
// {"metric":"rpe","delta","delta_unit","align","scale","pairs","trans_{rmse,mean,median,std,min,
//  max}_m","rot_{rmse,mean,median,std,min,max}_deg"}
nlohmann::json toJson(const RpeResult& result);
// {"metric":"kitti","t_rel_percent","r_rel_deg_per_100m","segments","frames","path_length_m",
//  "align","scale","step_frames","lengths":[{"length_m","segments","t_rel_percent",
//  "r_rel_deg_per_100m"}]}
nlohmann::json toJson(const KittiResult& result);

std::string formatTable(const AteResult& result);
std::string formatTable(const RpeResult& result);
std::string formatTable(const KittiResult& result);

}  // namespace edgeslam
