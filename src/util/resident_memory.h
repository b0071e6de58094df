#pragma once
// Resident memory (VmRSS) of a process, from /proc: what the server reports of itself and what the
// tests watch of the processes they start.
#include <sys/types.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

namespace edgeslam {

// A "Vm...:" line of /proc/PID/status in bytes; 0 when unknown (no /proc, or the process has
// gone).
inline std::uint64_t procStatusBytes(pid_t pid, const std::string& field) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (in >> key) {
    if (key == field) {
      std::uint64_t kb = 0;
      in >> kb;
      return kb * 1024;
    }
    in.ignore(1 << 12, '\n');
  }
  return 0;
}

// Bytes resident now (VmRSS).
inline std::uint64_t residentBytes(pid_t pid = ::getpid()) {
  return procStatusBytes(pid, "VmRSS:");
}

// The most bytes the process has had resident so far (VmHWM, its high-water mark).
inline std::uint64_t peakResidentBytes(pid_t pid = ::getpid()) {
  return procStatusBytes(pid, "VmHWM:");
}

}  // namespace edgeslam
