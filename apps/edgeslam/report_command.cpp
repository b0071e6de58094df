// `edgeslam report OUT_DIR`: one self-contained HTML page for a finished run, from the files the
// run wrote (trajectory.tum, groundtruth.tum, frames.csv, metrics.json). The charts are uPlot's,
// inlined with its script and style (the copy built into the binary for the viewer), so the page
// makes no request of any kind.
#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.h"
#include "eval/alignment.h"
#include "eval/association.h"
#include "eval/ate.h"
#include "eval/markup_escape.h"
#include "io/trajectory.h"
#include "viz/web_assets.h"

namespace edgeslam::cli {
namespace {

namespace fs = std::filesystem;

struct ReportOptions {
  fs::path run_dir;
  fs::path output;        // default: run_dir/report.html
  fs::path ground_truth;  // default: run_dir/groundtruth.tum when there
};

std::string readFile(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(fmt::format("cannot read {}", path.string()));
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}

std::string_view webAsset(std::string_view path) {
  for (const viz::WebAsset& asset : viz::webAssets()) {
    if (asset.path == path) return asset.body;
  }
  throw std::logic_error(fmt::format("web asset {} is not built in", path));
}

// Text that goes inside a <script> element: "</" would end it early.
std::string scriptSafe(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (std::size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') out += "\\";
  }
  return out;
}

// frames.csv as columns of numbers by header name (state: 1 when "ok"); absent columns are left
// out, so runs written before a column existed still report.
std::map<std::string, std::vector<double>> readFrameLog(const fs::path& path) {
  std::ifstream in(path);
  std::map<std::string, std::vector<double>> columns;
  std::string line;
  if (!std::getline(in, line)) return columns;
  std::vector<std::string> names;
  std::stringstream header(line);
  for (std::string name; std::getline(header, name, ',');) names.push_back(name);
  while (std::getline(in, line)) {
    std::stringstream row(line);
    std::size_t i = 0;
    for (std::string cell; std::getline(row, cell, ',') && i < names.size(); ++i) {
      double value = 0.0;
      if (names[i] == "state") {
        value = cell == "ok" ? 1.0 : 0.0;
      } else {
        try {
          value = std::stod(cell);
        } catch (const std::exception&) {
          throw std::runtime_error(
              fmt::format("{}: bad {} value '{}'", path.string(), names[i], cell));
        }
      }
      columns[names[i]].push_back(value);
    }
  }
  return columns;
}

nlohmann::json framesJson(const std::map<std::string, std::vector<double>>& columns) {
  const auto column = [&](const std::string& name, double missing) {
    const auto it = columns.find(name);
    const std::size_t n = columns.at("frame").size();
    if (it == columns.end() || it->second.size() != n) return std::vector<double>(n, missing);
    return it->second;
  };
  return {{"frame", column("frame", 0.0)},
          {"client_ms", column("client_ms", 0.0)},
          {"e2e_ms", column("e2e_ms", 0.0)},
          {"uplink_bytes", column("uplink_bytes", 0.0)},
          {"downlink_bytes", column("downlink_bytes", 0.0)},
          {"adaptation_row", column("adaptation_row", -1.0)},
          {"features_culled", column("features_culled", 0.0)}};
}

// The estimate aligned to the ground truth: the error over time and a top view on the two axes
// along which the ground truth spreads most.
nlohmann::json trajectoryJson(const Trajectory& ground_truth, const Trajectory& estimate,
                              AlignMode align, nlohmann::json& error) {
  const PosePairs pairs = associateByTimestamp(ground_truth, estimate);
  const AteResult ate = computeAte(pairs, align);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : ate.gt_positions) mean += p;
  mean /= static_cast<double>(ate.gt_positions.size());
  Eigen::Vector3d spread = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : ate.gt_positions) spread += (p - mean).cwiseAbs2();
  std::array<int, 3> axes{0, 1, 2};
  std::sort(axes.begin(), axes.end(), [&](int a, int b) { return spread[a] > spread[b]; });
  std::sort(axes.begin(), axes.begin() + 2);
  const auto coordinate = [](const std::vector<Eigen::Vector3d>& positions, int axis) {
    std::vector<double> out;
    out.reserve(positions.size());
    for (const Eigen::Vector3d& p : positions) out.push_back(std::round(p[axis] * 1e4) / 1e4);
    return out;
  };
  const double t0 = ate.timestamps.empty() ? 0.0 : ate.timestamps.front();
  std::vector<double> t;
  for (const double stamp : ate.timestamps) t.push_back(std::round((stamp - t0) * 1e3) / 1e3);
  error = {{"t", t}, {"error_m", ate.errors}, {"rmse_m", ate.translation.rmse}};
  const std::array<const char*, 3> names{"x", "y", "z"};
  return {{"axes", {names[axes[0]], names[axes[1]]}},
          {"align", toString(align)},
          {"truth_x", coordinate(ate.gt_positions, axes[0])},
          {"truth_y", coordinate(ate.gt_positions, axes[1])},
          {"estimate_x", coordinate(ate.aligned_est_positions, axes[0])},
          {"estimate_y", coordinate(ate.aligned_est_positions, axes[1])}};
}

// metrics.json's figures as "a.b.c: value" rows (arrays of more than a few values left out).
void flattenMetrics(const nlohmann::json& value, const std::string& prefix, std::string& rows) {
  if (value.is_object()) {
    for (const auto& [key, child] : value.items()) {
      flattenMetrics(child, prefix.empty() ? key : prefix + "." + key, rows);
    }
    return;
  }
  if (value.is_array() && value.size() > 8) return;
  std::string text = value.is_string() ? value.get<std::string>() : value.dump();
  if (value.is_number_float()) text = fmt::format("{:.6g}", value.get<double>());
  rows +=
      fmt::format("<tr><th>{}</th><td>{}</td></tr>\n", escapeMarkup(prefix), escapeMarkup(text));
}

constexpr const char* kStyle = R"(
body { font: 14px/1.45 system-ui, sans-serif; color: #1d232b; margin: 20px; max-width: 940px; }
h1 { font-size: 20px; margin: 0 0 4px; } h2 { font-size: 16px; margin: 22px 0 2px; }
.note { color: #5b6573; margin: 0 0 6px; font-size: 13px; }
table.summary { border-collapse: collapse; } table.summary th { text-align: left; font-weight: normal;
  color: #5b6573; padding: 1px 16px 1px 0; } table.summary td { font-variant-numeric: tabular-nums; }
details { margin-top: 12px; } summary { cursor: pointer; color: #1f7ae0; }
)";

int writeReport(const ReportOptions& o) {
  const fs::path dir = o.run_dir;
  if (!fs::is_directory(dir))
    throw std::runtime_error(fmt::format("no run folder {}", dir.string()));
  const fs::path trajectory_file = dir / "trajectory.tum";
  if (!fs::exists(trajectory_file)) {
    throw std::runtime_error(
        fmt::format("{} has no trajectory.tum (write a run there with "
                    "`edgeslam run ... --out {}`)",
                    dir.string(), dir.string()));
  }
  nlohmann::json metrics = nlohmann::json::object();
  if (fs::exists(dir / "metrics.json"))
    metrics = nlohmann::json::parse(readFile(dir / "metrics.json"));
  nlohmann::json data = nlohmann::json::object();
  const Trajectory estimate = readTumTrajectory(trajectory_file);
  const fs::path gt_file = o.ground_truth.empty() ? dir / "groundtruth.tum" : o.ground_truth;
  std::string truth_note = "no ground truth (groundtruth.tum or --ground-truth)";
  if (fs::exists(gt_file)) {
    const AlignMode align =
        metrics.value("sensor", std::string()) == "mono" ? AlignMode::kSim3 : AlignMode::kSe3;
    nlohmann::json error;
    data["top_view"] = trajectoryJson(readTumTrajectory(gt_file), estimate, align, error);
    data["error"] = std::move(error);
    truth_note = "ground truth: " + gt_file.string();
  } else if (!o.ground_truth.empty()) {
    throw std::runtime_error(fmt::format("no ground truth at {}", gt_file.string()));
  }
  if (fs::exists(dir / "frames.csv")) {
    const auto columns = readFrameLog(dir / "frames.csv");
    if (columns.contains("frame")) data["frames"] = framesJson(columns);
  }
  std::string rows;
  flattenMetrics(metrics, "", rows);
  const std::string title = fmt::format("edgeslam run: {}", fs::absolute(dir).filename().string());
  const std::string html = fmt::format(
      R"(<!doctype html>
<html lang="en"><head><meta charset="utf-8"><title>{0}</title>
<meta name="viewport" content="width=device-width, initial-scale=1">
<style>{1}</style><style>{2}</style>
</head><body>
<h1>{0}</h1>
<p class="note">{3} estimated poses; {4}</p>
<div id="charts"></div>
<details><summary>every figure in metrics.json</summary>
<table class="summary">{5}</table></details>
<script>{6}</script>
<script>window.EDGESLAM_REPORT = {7};</script>
<script>{8}</script>
</body></html>
)",
      escapeMarkup(title), webAsset("/lib/uPlot.min.css"), kStyle, estimate.size(),
      escapeMarkup(truth_note), rows, scriptSafe(webAsset("/lib/uPlot.iife.min.js")),
      scriptSafe(data.dump()), scriptSafe(webAsset("/report.js")));
  const fs::path output = o.output.empty() ? dir / "report.html" : o.output;
  std::ofstream out(output, std::ios::binary);
  out << html;
  if (!out) throw std::runtime_error(fmt::format("cannot write {}", output.string()));
  spdlog::info("report written to {} ({} KB)", output.string(), html.size() / 1024);
  return 0;
}

void addReportCommand(CLI::App& app) {
  auto o = std::make_shared<ReportOptions>();
  auto* cmd = app.add_subcommand(
      "report", "One self-contained HTML page for a finished run (from `run --out DIR`)");
  cmd->add_option("OUT_DIR", o->run_dir, "The run's output folder")->required();
  cmd->add_option("--out", o->output, "The page to write (default: OUT_DIR/report.html)");
  cmd->add_option("--ground-truth", o->ground_truth,
                  "Ground truth (TUM format; default: OUT_DIR/groundtruth.tum when there)");
  cmd->callback([o] { exitCode() = writeReport(*o); });
}

const CommandRegistration kReportCommandRegistration{45, addReportCommand};

}  // namespace
}  // namespace edgeslam::cli
