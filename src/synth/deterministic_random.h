#pragma once
// Random numbers that are the same for a seed on every platform: std::mt19937_64 is fully
// specified by the standard, the std::*_distribution classes are not, so the mapping is ours.
#include <cstdint>
#include <random>

namespace edgeslam {

class DeterministicRandom {
 public:
  explicit DeterministicRandom(std::uint64_t seed) : engine_(seed) {}

  // Uniform in [0, 1) with 53 random bits.
  double unit() { return static_cast<double>(engine_() >> 11) * 0x1.0p-53; }
  double uniform(double low, double high) { return low + (high - low) * unit(); }
  // Uniform integer in [0, count); count must be > 0.
  std::size_t index(std::size_t count) {
    return static_cast<std::size_t>(unit() * static_cast<double>(count)) % count;
  }
  bool chance(double probability) { return unit() < probability; }

 private:
  std::mt19937_64 engine_;
};

}  // namespace edgeslam
