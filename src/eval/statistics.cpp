#include "eval/statistics.h"

#include <algorithm>
#include <cmath>

#include "eval/eval_error.h"

namespace edgeslam {

ErrorStatistics computeStatistics(std::vector<double> values) {
  if (values.empty()) throw EvalError("no errors to summarise");
  ErrorStatistics s;
  s.count = values.size();
  const double n = static_cast<double>(values.size());
  double sum = 0.0;
  double sum_squares = 0.0;
  for (const double v : values) {
    sum += v;
    sum_squares += v * v;
  }
  s.mean = sum / n;
  s.rmse = std::sqrt(sum_squares / n);
  double centred_squares = 0.0;
  for (const double v : values) centred_squares += (v - s.mean) * (v - s.mean);
  s.std = std::sqrt(centred_squares / n);
  std::sort(values.begin(), values.end());
  s.min = values.front();
  s.max = values.back();
  const std::size_t mid = values.size() / 2;
  s.median = values.size() % 2 == 1 ? values[mid] : 0.5 * (values[mid - 1] + values[mid]);
  return s;
}

}  // namespace edgeslam
