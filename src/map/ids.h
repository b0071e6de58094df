#pragma once
// Stable 64-bit ids for map elements. The top byte names who created the element (0 = edge/global
// map, 1.. = a client), so ids made on both sides of the wire never collide.
#include <atomic>
#include <cstdint>

namespace edgeslam {

using KeyFrameId = std::uint64_t;
using MapPointId = std::uint64_t;
constexpr std::uint64_t kInvalidId = 0;

constexpr std::uint8_t idOrigin(std::uint64_t id) {
  return static_cast<std::uint8_t>(id >> 56);
}

class IdAllocator {
 public:
  explicit IdAllocator(std::uint8_t origin = 0)
      : prefix_(static_cast<std::uint64_t>(origin) << 56) {}
  std::uint64_t next() { return prefix_ | counter_.fetch_add(1, std::memory_order_relaxed); }
  // Makes later ids larger than `id` (after loading a saved map).
  void advancePast(std::uint64_t id) {
    const std::uint64_t local = id & ((std::uint64_t{1} << 56) - 1);
    std::uint64_t current = counter_.load();
    while (current <= local && !counter_.compare_exchange_weak(current, local + 1)) {
    }
  }

 private:
  std::uint64_t prefix_;
  std::atomic<std::uint64_t> counter_{1};
};

}  // namespace edgeslam
