// How much of one core the host takes away: a busy loop on the core reads the clock and records
// every gap longer than a threshold (the thread was not running). On a shared virtual machine the
// gaps (tens of ms) set a floor under any per-frame p99 measured there.
// Usage: host_jitter [seconds = 10] [threshold_ms = 5]; prints one JSON object.
#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <exception>
#include <string>
#include <vector>

int main(int argc, char** argv) {
  double seconds = 10.0;
  double threshold_ms = 5.0;
  try {
    if (argc > 1) seconds = std::stod(argv[1]);
    if (argc > 2) threshold_ms = std::stod(argv[2]);
  } catch (const std::exception&) {
    std::fprintf(stderr, "usage: host_jitter [seconds] [threshold_ms]\n");
    return 2;
  }
  if (!(seconds > 0.0) || !(threshold_ms > 0.0)) {
    std::fprintf(stderr, "host_jitter: seconds and threshold_ms must be positive\n");
    return 2;
  }
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  auto last = start;
  std::vector<double> gaps;
  while (std::chrono::duration<double>(last - start).count() < seconds) {
    const auto now = Clock::now();
    const double gap_ms = std::chrono::duration<double, std::milli>(now - last).count();
    if (gap_ms > threshold_ms) gaps.push_back(gap_ms);
    last = now;
  }
  double lost_ms = 0.0, worst_ms = 0.0;
  int over_20 = 0;
  for (double g : gaps) {
    lost_ms += g;
    worst_ms = std::max(worst_ms, g);
    if (g > 20.0) ++over_20;
  }
  fmt::print(
      "{{\"seconds\": {:.1f}, \"threshold_ms\": {:.1f}, \"gaps\": {}, \"gaps_over_20ms\": {}, "
      "\"lost_ms\": {:.1f}, \"worst_ms\": {:.1f}}}\n",
      seconds, threshold_ms, gaps.size(), over_20, lost_ms, worst_ms);
  return 0;
}
