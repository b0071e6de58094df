#pragma once
// Pre-drawn RANSAC minimal sets, so that competing models (H and F) are tried on the same samples
// and results are reproducible from a seed.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace edgeslam {

struct SampleSets {
  int sample_size = 0;
  int count = 0;
  std::vector<int> indices;  // count * sample_size indices, distinct within each set

  const int* set(int i) const { return indices.data() + static_cast<size_t>(i) * sample_size; }
};

// Throws std::invalid_argument when num_points < sample_size or a size is not positive.
SampleSets drawSampleSets(int num_points, int sample_size, int count, uint64_t seed);

}  // namespace edgeslam
