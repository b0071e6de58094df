#include "geometry/ransac_sampling.h"

#include <fmt/format.h>

#include <numeric>
#include <random>
#include <stdexcept>

namespace edgeslam {

SampleSets drawSampleSets(int num_points, int sample_size, int count, uint64_t seed) {
  if (sample_size <= 0 || count <= 0 || num_points < sample_size) {
    throw std::invalid_argument(
        fmt::format("drawSampleSets: need 0 < sample_size <= num_points and count > 0 (got "
                    "num_points={}, sample_size={}, count={})",
                    num_points, sample_size, count));
  }
  SampleSets sets;
  sets.sample_size = sample_size;
  sets.count = count;
  sets.indices.reserve(static_cast<size_t>(sample_size) * count);

  std::mt19937_64 rng(seed);
  std::vector<int> pool(num_points);
  std::iota(pool.begin(), pool.end(), 0);
  for (int s = 0; s < count; ++s) {
    // Partial Fisher-Yates: the first sample_size entries become a uniform draw without
    // replacement; the pool stays a permutation so the next set can reuse it.
    for (int k = 0; k < sample_size; ++k) {
      std::uniform_int_distribution<int> pick(k, num_points - 1);
      std::swap(pool[k], pool[pick(rng)]);
      sets.indices.push_back(pool[k]);
    }
  }
  return sets;
}

}  // namespace edgeslam
