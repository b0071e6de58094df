#pragma once
// Collects durations (or any samples) and reports median / p90 / p99 / max as DESIGN.md's metrics
// ask.
#include <chrono>
#include <cstddef>
#include <vector>

namespace edgeslam {

struct PercentileSummary {
  std::size_t count = 0;
  double median = 0.0;
  double p90 = 0.0;
  double p95 = 0.0;
  double p99 = 0.0;
  double max = 0.0;
  double mean = 0.0;
};

class SampleStats {
 public:
  void add(double value) { samples_.push_back(value); }
  std::size_t count() const { return samples_.size(); }
  const std::vector<double>& samples() const { return samples_; }
  // Percentiles by linear interpolation between order statistics; all zero when empty.
  PercentileSummary summary() const;

 private:
  std::vector<double> samples_;
};

// Percentile q in [0, 1] of unsorted values (linear interpolation); 0 when empty.
double percentile(std::vector<double> values, double q);

class Stopwatch {
 public:
  Stopwatch() : start_(std::chrono::steady_clock::now()) {}
  void restart() { start_ = std::chrono::steady_clock::now(); }
  double elapsedMs() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start_)
        .count();
  }

 private:
  std::chrono::steady_clock::time_point start_;
};

}  // namespace edgeslam
