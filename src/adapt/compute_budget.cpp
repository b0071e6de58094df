#include "adapt/compute_budget.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace edgeslam {

int ComputeStep::features(int configured) const {
  return std::max(1, static_cast<int>(std::lround(configured * feature_fraction)));
}

int ComputeStep::levels(int configured) const {
  return max_levels > 0 ? std::max(1, std::min(configured, max_levels)) : configured;
}

const std::array<ComputeStep, kComputeSteps>& computeSteps() {
  static const std::array<ComputeStep, kComputeSteps> steps{{
      {.feature_fraction = 1.0, .max_levels = 0},
      {.feature_fraction = 0.8, .max_levels = 0},
      {.feature_fraction = 0.7, .max_levels = 6},
      {.feature_fraction = 0.6, .max_levels = 5},
  }};
  return steps;
}

void ComputeBudgetOptions::validate() const {
  if (!(std::isfinite(period_ms) && period_ms > 0.0)) {
    throw std::invalid_argument(
        fmt::format("compute budget: frame period {} ms is not positive", period_ms));
  }
  if (window == 0) throw std::invalid_argument("compute budget: the window must hold frames");
  if (!(under_budget > 0.0 && under_budget < over_budget && std::isfinite(over_budget))) {
    throw std::invalid_argument(
        fmt::format("compute budget: budgets must satisfy 0 < under ({}) < over ({})", under_budget,
                    over_budget));
  }
  if (!(skipped_share > 0.0) || up_windows < 1) {
    throw std::invalid_argument("compute budget: skipped_share and up_windows must be positive");
  }
}

ComputeBudget::ComputeBudget(ComputeBudgetOptions options) : options_(options) {
  options_.validate();
  window_ms_.reserve(options_.window);
}

bool ComputeBudget::onFrame(double frame_ms, std::size_t skipped_before) {
  ++frames_[step_];
  window_ms_.push_back(std::isfinite(frame_ms) ? frame_ms : options_.period_ms);
  window_skipped_ += skipped_before;
  if (window_ms_.size() < options_.window) return false;
  const bool changed = decide();
  window_ms_.clear();
  window_skipped_ = 0;
  return changed;
}

bool ComputeBudget::decide() {
  auto middle = window_ms_.begin() + static_cast<std::ptrdiff_t>(window_ms_.size() / 2);
  std::nth_element(window_ms_.begin(), middle, window_ms_.end());
  const double median_ms = *middle;
  const bool skipping = static_cast<double>(window_skipped_) >=
                        options_.skipped_share * static_cast<double>(window_ms_.size());
  if (median_ms > options_.over_budget * options_.period_ms || skipping) {
    windows_with_room_ = 0;
    if (step_ + 1 >= kComputeSteps) return false;
    ++step_;
    ++switches_;
    deepest_ = std::max(deepest_, step_);
    return true;
  }
  if (median_ms < options_.under_budget * options_.period_ms && window_skipped_ == 0) {
    if (++windows_with_room_ < options_.up_windows || step_ == 0) return false;
    windows_with_room_ = 0;
    --step_;
    ++switches_;
    return true;
  }
  windows_with_room_ = 0;
  return false;
}

}  // namespace edgeslam
