#pragma once
// Summary statistics of a list of non-negative errors, the way the TUM benchmark prints them
// (std is the population standard deviation, median the mean of the two middle values).
#include <cstddef>
#include <vector>

namespace edgeslam {

struct ErrorStatistics {
  double rmse = 0.0;
  double mean = 0.0;
  double median = 0.0;
  double std = 0.0;
  double min = 0.0;
  double max = 0.0;
  std::size_t count = 0;
};

// Throws EvalError when `values` is empty.
ErrorStatistics computeStatistics(std::vector<double> values);

}  // namespace edgeslam
