#include "repeat_passes.h"

#include <fmt/format.h>
#include <malloc.h>

#include <algorithm>
#include <cmath>

#include "eval/association.h"
#include "eval/ate.h"
#include "modes/slam_system.h"
#include "util/resident_memory.h"

namespace edgeslam::cli {
namespace {

Trajectory within(const Trajectory& trajectory, double first, double last) {
  Trajectory part;
  for (const StampedPose& p : trajectory) {
    if (p.timestamp >= first && p.timestamp <= last) part.push_back(p);
  }
  return part;
}

std::uint64_t heapInUseBytes() {
  const struct mallinfo2 heap = mallinfo2();
  return heap.uordblks + heap.hblkhd;
}

double rmse(const std::vector<double>& errors) {
  if (errors.empty()) return 0.0;
  double sum = 0.0;
  for (double e : errors) sum += e * e;
  return std::sqrt(sum / static_cast<double>(errors.size()));
}

}  // namespace

PassRecord& PassLog::current(std::size_t index, double timestamp) {
  if (!open_) {
    PassRecord pass;
    pass.first_frame = index;
    pass.first_timestamp = timestamp;
    passes_.push_back(pass);
    open_ = true;
  }
  return passes_.back();
}

void PassLog::addFrame(std::size_t index, double timestamp, const TrackResult& result) {
  PassRecord& pass = current(index, timestamp);
  pass.last_frame = index;
  pass.last_timestamp = timestamp;
  ++pass.frames;
  if (result.state == TrackingState::kOk) ++pass.tracked;
  if (result.state == TrackingState::kLost) ++pass.lost;
  if (result.relocalized) ++pass.relocalized;
  if (result.new_keyframe) ++pass.keyframes_made;
  const std::size_t in_pass = frames_per_pass_ == 0 ? pass.frames : index % frames_per_pass_;
  const bool second_half = frames_per_pass_ == 0 || 2 * in_pass >= frames_per_pass_;
  if (second_half && in_pass % kHeapSampleEvery == 0) {
    const std::uint64_t heap = heapInUseBytes();
    if (pass.heap_floor_bytes == 0 || heap < pass.heap_floor_bytes) pass.heap_floor_bytes = heap;
  }
}

void PassLog::beforeFrame(std::size_t index, const SlamSystem& slam,
                          const std::function<std::optional<EdgeMapSize>()>& edge_map,
                          double wall_s) {
  if (!open_ || frames_per_pass_ == 0) return;
  if (index / frames_per_pass_ == passes_.back().first_frame / frames_per_pass_) return;
  close(slam, edge_map, wall_s);
}

void PassLog::finish(const SlamSystem& slam,
                     const std::function<std::optional<EdgeMapSize>()>& edge_map, double wall_s) {
  if (open_) close(slam, edge_map, wall_s);
}

void PassLog::close(const SlamSystem& slam,
                    const std::function<std::optional<EdgeMapSize>()>& edge_map, double wall_s) {
  PassRecord& pass = passes_.back();
  const std::optional<EdgeMapSize> edge = edge_map ? edge_map() : std::nullopt;
  pass.map_keyframes = edge ? edge->keyframes : slam.keyFrameCount();
  pass.map_points = edge ? edge->points : slam.mapPointCount();
  pass.map_resets = slam.mapResets();
  pass.rss_bytes = residentBytes();
  pass.peak_rss_bytes = peakResidentBytes();
  pass.heap_in_use_bytes = heapInUseBytes();
  if (pass.heap_floor_bytes == 0 || pass.heap_in_use_bytes < pass.heap_floor_bytes) {
    pass.heap_floor_bytes = pass.heap_in_use_bytes;
  }
  pass.wall_s = wall_s;
  open_ = false;
}

nlohmann::json PassLog::json(const Trajectory& ground_truth, const Trajectory& estimate,
                             AlignMode align) const {
  std::optional<AteResult> whole;
  if (!ground_truth.empty() && estimate.size() >= 3) {
    const PosePairs pairs = associateByTimestamp(ground_truth, estimate);
    if (pairs.size() >= minimumPairsForAlignment(align)) whole = computeAte(pairs, align);
  }
  nlohmann::json out = nlohmann::json::array();
  for (std::size_t k = 0; k < passes_.size(); ++k) {
    const PassRecord& p = passes_[k];
    nlohmann::json pass = {{"pass", k + 1},
                           {"first_frame", p.first_frame},
                           {"last_frame", p.last_frame},
                           {"frames", p.frames},
                           {"tracked", p.tracked},
                           {"lost", p.lost},
                           {"relocalized", p.relocalized},
                           {"keyframes_made", p.keyframes_made},
                           {"map_keyframes", p.map_keyframes},
                           {"map_points", p.map_points},
                           {"map_resets", p.map_resets},
                           {"rss_bytes", p.rss_bytes},
                           {"peak_rss_bytes", p.peak_rss_bytes},
                           {"heap_in_use_bytes", p.heap_in_use_bytes},
                           {"heap_floor_bytes", p.heap_floor_bytes},
                           {"wall_s", p.wall_s}};
    const Trajectory gt = within(ground_truth, p.first_timestamp, p.last_timestamp);
    const Trajectory est = within(estimate, p.first_timestamp, p.last_timestamp);
    if (!gt.empty() && est.size() >= 3) {
      const PosePairs pairs = associateByTimestamp(gt, est);
      if (pairs.size() >= minimumPairsForAlignment(align)) {
        const AteResult ate = computeAte(pairs, align);
        pass["ate"] = {{"rmse_m", ate.translation.rmse},
                       {"pairs", ate.translation.count},
                       {"align", toString(align)}};
      }
    }
    if (whole) {
      std::vector<double> errors;
      for (std::size_t i = 0; i < whole->errors.size(); ++i) {
        const double t = whole->timestamps[i];
        if (t >= p.first_timestamp && t <= p.last_timestamp) errors.push_back(whole->errors[i]);
      }
      if (!errors.empty()) pass["ate_in_run_alignment_rmse_m"] = rmse(errors);
    }
    out.push_back(pass);
  }
  return out;
}

void PassLog::print() const {
  for (std::size_t k = 0; k < passes_.size(); ++k) {
    const PassRecord& p = passes_[k];
    fmt::print(
        "  pass {:<3}     tracked {}, lost {}, relocalised {}; map {} keyframes, {} points; RSS "
        "{:.0f} MB (peak {:.0f} MB), heap floor {:.0f} MB\n",
        k + 1, p.tracked, p.lost, p.relocalized, p.map_keyframes, p.map_points,
        static_cast<double>(p.rss_bytes) / 1e6, static_cast<double>(p.peak_rss_bytes) / 1e6,
        static_cast<double>(p.heap_floor_bytes) / 1e6);
  }
}

}  // namespace edgeslam::cli
