#pragma once
// Wall-clock and thread CPU time of a block, so that timings stay meaningful on a busy machine.
#include <chrono>
#include <ctime>

namespace edgeslam::test {

class CpuTimer {
 public:
  CpuTimer() : wall_start_(std::chrono::steady_clock::now()), cpu_start_(threadCpuSeconds()) {}
  double wallMs() const {
    return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - wall_start_)
        .count();
  }
  double cpuMs() const { return 1e3 * (threadCpuSeconds() - cpu_start_); }

 private:
  static double threadCpuSeconds() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  std::chrono::steady_clock::time_point wall_start_;
  double cpu_start_;
};

}  // namespace edgeslam::test
