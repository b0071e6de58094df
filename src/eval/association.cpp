#include "eval/association.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>

#include "eval/eval_error.h"

namespace edgeslam {
namespace {

struct Candidate {
  double dt;
  double gt_time;
  double est_time;
  std::size_t gt_index;
  std::size_t est_index;
};

std::vector<std::size_t> indicesSortedByTime(const Trajectory& trajectory) {
  std::vector<std::size_t> order(trajectory.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return trajectory[a].timestamp < trajectory[b].timestamp;
  });
  return order;
}

}  // namespace

PosePairs associateByTimestamp(const Trajectory& gt, const Trajectory& est, double max_dt) {
  if (!(max_dt > 0.0) || !std::isfinite(max_dt)) {
    throw EvalError(fmt::format("maximum time difference must be positive, got {}", max_dt));
  }
  const std::vector<std::size_t> gt_order = indicesSortedByTime(gt);
  std::vector<double> gt_times(gt_order.size());
  for (std::size_t k = 0; k < gt_order.size(); ++k) gt_times[k] = gt[gt_order[k]].timestamp;

  // Only ground-truth poses within max_dt of an estimate can pair with it: find them by bisection.
  std::vector<Candidate> candidates;
  for (std::size_t e = 0; e < est.size(); ++e) {
    const double t = est[e].timestamp;
    auto it = std::lower_bound(gt_times.begin(), gt_times.end(), t - max_dt);
    for (; it != gt_times.end() && *it <= t + max_dt; ++it) {
      const double dt = std::abs(*it - t);
      if (dt < max_dt) {
        const auto k = static_cast<std::size_t>(it - gt_times.begin());
        candidates.push_back({dt, *it, t, gt_order[k], e});
      }
    }
  }
  std::sort(candidates.begin(), candidates.end(), [](const Candidate& a, const Candidate& b) {
    return std::tie(a.dt, a.gt_time, a.est_time, a.gt_index, a.est_index) <
           std::tie(b.dt, b.gt_time, b.est_time, b.gt_index, b.est_index);
  });

  std::vector<bool> gt_used(gt.size(), false);
  std::vector<bool> est_used(est.size(), false);
  PosePairs pairs;
  for (const Candidate& c : candidates) {
    if (gt_used[c.gt_index] || est_used[c.est_index]) continue;
    gt_used[c.gt_index] = true;
    est_used[c.est_index] = true;
    pairs.push_back({c.gt_time, c.est_time, c.gt_index, c.est_index, gt[c.gt_index].pose,
                     est[c.est_index].pose});
  }
  std::sort(pairs.begin(), pairs.end(), [](const PosePair& a, const PosePair& b) {
    return std::tie(a.gt_timestamp, a.est_timestamp) < std::tie(b.gt_timestamp, b.est_timestamp);
  });
  return pairs;
}

PosePairs associateByIndex(const Trajectory& gt, const Trajectory& est) {
  if (gt.size() != est.size()) {
    throw EvalError(
        fmt::format("pairing by index needs equally long trajectories: ground truth has {} poses, "
                    "estimate {}",
                    gt.size(), est.size()));
  }
  PosePairs pairs;
  pairs.reserve(gt.size());
  for (std::size_t i = 0; i < gt.size(); ++i) {
    pairs.push_back({gt[i].timestamp, est[i].timestamp, i, i, gt[i].pose, est[i].pose});
  }
  return pairs;
}

}  // namespace edgeslam
