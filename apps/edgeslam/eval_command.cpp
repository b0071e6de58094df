// `edgeslam eval ate|rpe|kitti`: compare an estimated trajectory with ground truth.
#include <fmt/format.h>

#include <exception>
#include <functional>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.h"
#include "eval/alignment.h"
#include "eval/ate.h"
#include "eval/kitti_metric.h"
#include "eval/report.h"
#include "eval/rpe.h"
#include "eval/svg_plot.h"
#include "eval/trajectory_input.h"
#include "io/trajectory.h"

namespace edgeslam::cli {
namespace {

struct EvalOptions {
  std::string gt;
  std::string est;
  std::string format = "auto";
  std::string align;
  std::string times;
  std::string plot;
  double max_dt = kDefaultMaxTimeDifference;
  bool json = false;
  double delta = 1.0;
  std::string delta_unit = "frames";
};

struct EvalInput {
  LoadedTrajectory gt;
  LoadedTrajectory est;
  PosePairs pairs;
};

void addCommonOptions(CLI::App* command, EvalOptions& o) {
  command->add_option("--gt", o.gt, "Ground-truth trajectory file (TUM or KITTI)")->required();
  command->add_option("--est", o.est, "Estimated trajectory file (TUM or KITTI)")->required();
  command
      ->add_option("--format", o.format,
                   "File format of both files (auto: 8 values per line "
                   "-> tum, 12 -> kitti)")
      ->check(CLI::IsMember({"auto", "tum", "kitti"}))
      ->capture_default_str();
  command->add_option("--align", o.align, "Alignment of the estimate to the ground truth")
      ->check(CLI::IsMember({"none", "se3", "sim3"}))
      ->capture_default_str();
  command->add_option("--max-dt", o.max_dt, "Largest time difference of associated poses [s]")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  command->add_option("--times", o.times, "Timestamps (one per line) of KITTI pose files");
  command->add_flag("--json", o.json, "Print exactly one JSON object instead of a table");
  command->add_option("--plot", o.plot, "Write a top-view SVG picture to this file");
}

EvalInput loadInput(const EvalOptions& o) {
  const std::vector<double> times = o.times.empty() ? std::vector<double>{} : readTimes(o.times);
  const TrajectoryFormat format = parseTrajectoryFormat(o.format);
  EvalInput input{loadTrajectory(o.gt, format, times), loadTrajectory(o.est, format, times), {}};
  input.pairs = pairTrajectories(input.gt, input.est, o.max_dt);
  return input;
}

std::string fileName(const LoadedTrajectory& t) {
  return t.path.filename().string();
}

std::string describeInput(const EvalInput& input) {
  return fmt::format("ground truth: {} ({} poses, {})\nestimate:     {} ({} poses, {})\n",
                     input.gt.path.string(), input.gt.poses.size(), toString(input.gt.format),
                     input.est.path.string(), input.est.poses.size(), toString(input.est.format));
}

void print(const EvalOptions& o, const EvalInput& input, nlohmann::json json,
           const std::string& table) {
  if (o.json) {
    json["gt_file"] = o.gt;
    json["est_file"] = o.est;
    std::cout << json.dump(2) << std::endl;
  } else {
    std::cout << describeInput(input) << table << std::flush;
  }
}

TrajectoryPlot basePlot(const EvalInput& input) {
  TrajectoryPlot plot;
  for (const StampedPose& p : input.gt.poses) plot.ground_truth.push_back(p.pose.translation());
  plot.plane = input.gt.format == TrajectoryFormat::kKitti ? PlotPlane::kXZ : PlotPlane::kAuto;
  plot.subtitle =
      fmt::format("estimate {}  vs  ground truth {}", fileName(input.est), fileName(input.gt));
  return plot;
}

void writePlot(const EvalOptions& o, const TrajectoryPlot& plot) {
  writeTrajectorySvg(o.plot, plot);
  if (!o.json) std::cout << "plot written to " << o.plot << "\n";
}

void runAte(const EvalOptions& o) {
  const EvalInput input = loadInput(o);
  const AteResult result = computeAte(input.pairs, parseAlignMode(o.align));
  print(o, input, toJson(result), formatTable(result));
  if (o.plot.empty()) return;
  TrajectoryPlot plot = basePlot(input);
  plot.title = fmt::format("ATE  RMSE {:.4f} m  ({} alignment, {} pairs)", result.translation.rmse,
                           toString(result.align), result.translation.count);
  plot.estimate = result.aligned_est_positions;
  plot.errors = result.errors;
  plot.error_label = "ATE [m]";
  writePlot(o, plot);
}

void runRpe(const EvalOptions& o) {
  const EvalInput input = loadInput(o);
  RpeOptions options;
  options.delta = o.delta;
  options.unit = parseDeltaUnit(o.delta_unit);
  options.align = parseAlignMode(o.align);
  const RpeResult result = computeRpe(input.pairs, options);
  print(o, input, toJson(result), formatTable(result));
  if (o.plot.empty()) return;
  TrajectoryPlot plot = basePlot(input);
  plot.title =
      fmt::format("RPE over {} {}  translation RMSE {:.4f} m, rotation RMSE {:.3f} deg", o.delta,
                  toString(options.unit), result.translation.rmse, result.rotation.rmse);
  const Sim3d alignment = alignPairs(
      input.pairs, options.align == AlignMode::kSim3 ? AlignMode::kSim3 : AlignMode::kSe3);
  // Each pose shows the error of the relative motion starting at it (the last ones repeat the
  // last error).
  std::vector<double> errors(input.pairs.size(), result.errors.back().translation_m);
  for (const RelativeError& e : result.errors) errors[e.first] = e.translation_m;
  for (std::size_t i = 0; i < input.pairs.size(); ++i) {
    plot.estimate.push_back(alignment * input.pairs[i].est.translation());
  }
  plot.errors = errors;
  plot.error_label = "RPE [m]";
  writePlot(o, plot);
}

void runKitti(const EvalOptions& o) {
  const EvalInput input = loadInput(o);
  KittiOptions options;
  options.align = parseAlignMode(o.align);
  const KittiResult result = computeKittiMetric(input.pairs, options);
  print(o, input, toJson(result), formatTable(result));
  if (o.plot.empty()) return;
  TrajectoryPlot plot = basePlot(input);
  plot.title = fmt::format("KITTI  t_rel {:.2f} %   r_rel {:.3f} deg/100 m  ({} segments)",
                           result.t_rel_percent, result.r_rel_deg_per_100m, result.segments.size());
  // The devkit does not align: the estimate is drawn as given (scaled when sim3), coloured by its
  // distance to the ground-truth pose of the same frame.
  for (const PosePair& pair : input.pairs) {
    const Eigen::Vector3d p = result.scale * pair.est.translation();
    plot.estimate.push_back(p);
    plot.errors.push_back((p - pair.gt.translation()).norm());
  }
  plot.error_label = "position error [m]";
  writePlot(o, plot);
}

// Runs a command, turning any failure into a clear message and a non-zero exit code.
std::function<void()> guarded(const std::string& name, std::function<void()> body) {
  return [name, body = std::move(body)] {
    try {
      body();
      exitCode() = 0;
    } catch (const CLI::Error&) {
      throw;  // a usage error: main() reports it
    } catch (const std::exception& e) {
      std::cerr << "edgeslam eval " << name << ": error: " << e.what() << std::endl;
      exitCode() = 1;
    }
  };
}

}  // namespace

void addEvalCommands(CLI::App& app) {
  auto* eval = app.add_subcommand("eval", "Evaluate an estimated trajectory against ground truth");
  eval->require_subcommand(1);

  auto ate_options = std::make_shared<EvalOptions>();
  ate_options->align = "se3";
  auto* ate = eval->add_subcommand(
      "ate", "Absolute trajectory error (translation) after least-squares alignment");
  addCommonOptions(ate, *ate_options);
  ate->callback(guarded("ate", [ate_options] { runAte(*ate_options); }));

  auto rpe_options = std::make_shared<EvalOptions>();
  rpe_options->align = "none";
  auto* rpe = eval->add_subcommand("rpe", "Relative pose error over a fixed delta");
  addCommonOptions(rpe, *rpe_options);
  rpe->add_option("--delta", rpe_options->delta, "Distance between the compared poses")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  rpe->add_option("--delta-unit", rpe_options->delta_unit, "Unit of --delta")
      ->check(CLI::IsMember({"frames", "seconds", "metres", "meters"}))
      ->capture_default_str();
  rpe->callback(guarded("rpe", [rpe_options] { runRpe(*rpe_options); }));

  auto kitti_options = std::make_shared<EvalOptions>();
  kitti_options->align = "none";
  auto* kitti = eval->add_subcommand(
      "kitti", "KITTI odometry metric: relative errors over 100..800 m segments");
  addCommonOptions(kitti, *kitti_options);
  kitti->callback(guarded("kitti", [kitti_options] { runKitti(*kitti_options); }));
}

const CommandRegistration kEvalCommandsRegistration{40, addEvalCommands};

}  // namespace edgeslam::cli
