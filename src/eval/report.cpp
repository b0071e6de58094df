#include "eval/report.h"

#include <fmt/format.h>

namespace edgeslam {
namespace {

void addStatistics(nlohmann::json& j, const ErrorStatistics& s, const std::string& prefix,
                   const std::string& unit) {
  j[prefix + "rmse" + unit] = s.rmse;
  j[prefix + "mean" + unit] = s.mean;
  j[prefix + "median" + unit] = s.median;
  j[prefix + "std" + unit] = s.std;
  j[prefix + "min" + unit] = s.min;
  j[prefix + "max" + unit] = s.max;
}

std::string statisticsRows(const ErrorStatistics& s, const std::string& unit, int decimals) {
  std::string out;
  const auto row = [&](const char* name, double value) {
    out += fmt::format("  {:<8}{:>14.{}f} {}\n", name, value, decimals, unit);
  };
  row("rmse", s.rmse);
  row("mean", s.mean);
  row("median", s.median);
  row("std", s.std);
  row("min", s.min);
  row("max", s.max);
  return out;
}

}  // namespace

nlohmann::json toJson(const AteResult& result) {
  nlohmann::json j;
  j["metric"] = "ate";
  addStatistics(j, result.translation, "", "_m");
  j["pairs"] = result.translation.count;
  j["scale"] = result.alignment.scale();
  j["align"] = toString(result.align);
  const Eigen::Quaterniond& q = result.alignment.rotation();
  const Eigen::Vector3d& t = result.alignment.translation();
  j["alignment"] = {{"scale", result.alignment.scale()},
                    {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}},
                    {"translation_m", {t.x(), t.y(), t.z()}}};
  return j;
}

nlohmann::json toJson(const RpeResult& result) {
  nlohmann::json j;
  j["metric"] = "rpe";
  j["delta"] = result.options.delta;
  j["delta_unit"] = toString(result.options.unit);
  j["align"] = toString(result.options.align);
  j["scale"] = result.scale;
  j["pairs"] = result.errors.size();
  addStatistics(j, result.translation, "trans_", "_m");
  addStatistics(j, result.rotation, "rot_", "_deg");
  return j;
}

nlohmann::json toJson(const KittiResult& result) {
  nlohmann::json j;
  j["metric"] = "kitti";
  j["t_rel_percent"] = result.t_rel_percent;
  j["r_rel_deg_per_100m"] = result.r_rel_deg_per_100m;
  j["segments"] = result.segments.size();
  j["frames"] = result.frames;
  j["path_length_m"] = result.path_length_m;
  j["align"] = toString(result.options.align);
  j["scale"] = result.scale;
  j["step_frames"] = result.options.step_frames;
  nlohmann::json lengths = nlohmann::json::array();
  for (const KittiLengthError& l : result.per_length) {
    lengths.push_back({{"length_m", l.length_m},
                       {"segments", l.segments},
                       {"t_rel_percent", l.t_rel_percent},
                       {"r_rel_deg_per_100m", l.r_rel_deg_per_100m}});
  }
  j["lengths"] = std::move(lengths);
  return j;
}

std::string formatTable(const AteResult& result) {
  std::string out = fmt::format("ATE, translation ({} alignment, {} pose pairs)\n",
                                toString(result.align), result.translation.count);
  out += statisticsRows(result.translation, "m", 6);
  out += fmt::format("  {:<8}{:>14.6f}\n", "scale", result.alignment.scale());
  return out;
}

std::string formatTable(const RpeResult& result) {
  std::string out = fmt::format("RPE over {} {} ({} alignment, scale {:.6f}, {} pose pairs)\n",
                                result.options.delta, toString(result.options.unit),
                                toString(result.options.align), result.scale, result.errors.size());
  out += "translation\n";
  out += statisticsRows(result.translation, "m", 6);
  out += "rotation\n";
  out += statisticsRows(result.rotation, "deg", 6);
  return out;
}

std::string formatTable(const KittiResult& result) {
  std::string out = fmt::format(
      "KITTI odometry metric ({} frames, ground-truth path {:.1f} m, step {} frames, {} "
      "alignment, scale {:.6f})\n",
      result.frames, result.path_length_m, result.options.step_frames,
      toString(result.options.align), result.scale);
  out += fmt::format("  {:>10} {:>9} {:>11} {:>18}\n", "length [m]", "segments", "t_rel [%]",
                     "r_rel [deg/100m]");
  for (const KittiLengthError& l : result.per_length) {
    out += fmt::format("  {:>10.0f} {:>9} {:>11.4f} {:>18.4f}\n", l.length_m, l.segments,
                       l.t_rel_percent, l.r_rel_deg_per_100m);
  }
  out += fmt::format("  {:>10} {:>9} {:>11.4f} {:>18.4f}\n", "all", result.segments.size(),
                     result.t_rel_percent, result.r_rel_deg_per_100m);
  return out;
}

}  // namespace edgeslam
