#include "route_following.h"

#include <fmt/format.h>

#include <algorithm>
#include <fstream>
#include <stdexcept>
#include <unordered_map>

#include "eval/association.h"
#include "eval/ate.h"
#include "nav/checkpoint_success.h"
#include "store/map_store.h"

namespace edgeslam::cli {
namespace {

RouteRecord readRoute(MapStore& store, const std::string& map, const std::string& name) {
  for (RouteRecord& route : store.listRoutes(map)) {
    if (route.name == name) return std::move(route);
  }
  throw std::runtime_error(
      fmt::format("--route: map '{}' in {} has no route '{}' (make one with `edgeslam route make`)",
                  map, store.location(), name));
}

double median(std::vector<double> values) {
  if (values.empty()) return 0.0;
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}

double maxOf(const std::vector<double>& values) {
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

}  // namespace

RouteFollowing::RouteFollowing(const std::filesystem::path& store_directory, const std::string& map,
                               const std::string& route, RouteFollowingOptions options)
    : map_(map), options_(options) {
  const auto store = openMapStore(store_directory, MapStoreAccess::kRead);
  navigator_.emplace(readRoute(*store, map, route), options_.navigator);
  const std::optional<MapSummary> summary = store->mapInfo(map);
  if (summary && !summary->metric) unit_ = "map units";
}

const Instruction& RouteFollowing::addFrame(std::size_t frame, double timestamp,
                                            const std::optional<SE3d>& T_cw) {
  instructions_.push_back({frame, timestamp, navigator_->update(T_cw)});
  return instructions_.back().instruction;
}

std::string RouteFollowing::lastText() const {
  if (instructions_.empty()) return "";
  return last().text(navigator_->route().checkpoints.size(), unit_);
}

int RouteFollowing::lastCheckpoint() const {
  if (instructions_.empty() || last().kind == InstructionKind::kNoPose) return -1;
  return static_cast<int>(last().checkpoint);
}

void RouteFollowing::writeInstructions(const std::filesystem::path& path) const {
  std::ofstream out(path);
  if (!out) throw std::runtime_error(path.string() + ": cannot be written");
  out << "frame,timestamp,instruction,checkpoint,turn_deg,distance_m,text\n";
  const std::size_t count = navigator_->route().checkpoints.size();
  for (const Entry& e : instructions_) {
    out << fmt::format("{},{:.6f},{},{},{:.1f},{:.3f},\"{}\"\n", e.frame, e.timestamp,
                       toString(e.instruction.kind), e.instruction.checkpoint + 1,
                       e.instruction.turn_deg, e.instruction.distance_m,
                       e.instruction.text(count, unit_));
  }
  if (!out) throw std::runtime_error(path.string() + ": cannot be written");
}

nlohmann::json RouteFollowing::json(const Trajectory& ground_truth,
                                    const Trajectory& stored_keyframes, const Trajectory& localised,
                                    AlignMode align) const {
  const RouteRecord& route = navigator_->route();
  nlohmann::json by_instruction = nlohmann::json::object();
  for (InstructionKind kind :
       {InstructionKind::kNoPose, InstructionKind::kGoStraight, InstructionKind::kTurnLeft,
        InstructionKind::kTurnRight, InstructionKind::kCheckpointReached,
        InstructionKind::kOffRoute, InstructionKind::kArrived}) {
    by_instruction[toString(kind)] = 0;
  }
  for (const Entry& e : instructions_) {
    by_instruction[toString(e.instruction.kind)] =
        by_instruction[toString(e.instruction.kind)].get<int>() + 1;
  }
  nlohmann::json out = {{"route", route.name},
                        {"map", map_},
                        {"source", route.source},
                        {"checkpoints", route.checkpoints.size()},
                        {"spacing_m", route.spacing_m},
                        {"reach_radius_m", navigator_->reachRadius()},
                        {"reached_by_estimate", navigator_->reached().size()},
                        {"arrived", navigator_->nextCheckpoint() >= route.checkpoints.size()},
                        {"frames_by_instruction", by_instruction}};
  if (ground_truth.empty()) return out;
  // The checkpoints into the truth's frame: by the stored keyframes of this stretch (independent
  // of how well this run localised), else by this run's poses.
  std::string alignment = "stored keyframes";
  PosePairs pairs = associateByTimestamp(ground_truth, stored_keyframes);
  if (pairs.size() < std::max<std::size_t>(5, minimumPairsForAlignment(align))) {
    alignment = "localised poses";
    pairs = associateByTimestamp(ground_truth, localised);
  }
  if (pairs.size() < minimumPairsForAlignment(align)) return out;
  const AteResult fit = computeAte(pairs, align);
  std::vector<Eigen::Vector3d> checkpoints;
  for (const Eigen::Vector3d& c : route.checkpoints) checkpoints.push_back(fit.alignment * c);
  std::unordered_map<double, Eigen::Vector3d> truth_at;  // the run's frames: exact timestamps
  std::vector<Eigen::Vector3d> truth;
  for (const StampedPose& p : ground_truth) {
    truth.push_back(p.pose.translation());
    truth_at.emplace(p.timestamp, p.pose.translation());
  }
  std::vector<AnnouncedCheckpoint> announced;
  std::size_t announced_without_truth = 0;
  for (std::size_t i = 0; i < instructions_.size(); ++i) {
    const Entry& e = instructions_[i];
    if (e.instruction.kind != InstructionKind::kCheckpointReached) continue;
    const auto found = truth_at.find(e.timestamp);
    if (found == truth_at.end()) {
      ++announced_without_truth;
      continue;
    }
    // Where the camera truly came from: the frame before this one, when it was localised too
    // (the navigator's path runs between poses in a row).
    std::optional<Eigen::Vector3d> from;
    if (i > 0 && instructions_[i - 1].instruction.kind != InstructionKind::kNoPose) {
      const auto before = truth_at.find(instructions_[i - 1].timestamp);
      if (before != truth_at.end()) from = before->second;
    }
    for (std::size_t k = e.instruction.first_checkpoint; k <= e.instruction.checkpoint; ++k) {
      announced.push_back({k, found->second, from});
    }
  }
  const CheckpointSuccess success =
      checkpointSuccess(checkpoints, announced, truth, options_.success_radius_m);
  out["success_radius_m"] = options_.success_radius_m;
  out["reached"] = success.reached;
  out["success_rate"] = success.rate;
  out["passed_by_true_path"] = success.passed;
  out["announced_without_truth"] = announced_without_truth;
  out["announced_error_m"] = {{"median", median(success.announced_error_m)},
                              {"max", maxOf(success.announced_error_m)}};
  out["closest_m"] = {{"median", median(success.closest_m)}, {"max", maxOf(success.closest_m)}};
  out["alignment"] = {{"by", alignment},
                      {"mode", toString(align)},
                      {"pairs", pairs.size()},
                      {"rmse_m", fit.translation.rmse}};
  return out;
}

}  // namespace edgeslam::cli
