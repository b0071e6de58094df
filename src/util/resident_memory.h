#pragma once
// Resident memory (VmRSS) of a process, from /proc: what the server reports of itself and what the
// tests watch of the processes they start.
#include <sys/types.h>
#include <unistd.h>

#include <cstdint>
#include <fstream>
#include <string>

namespace edgeslam {

// Bytes; 0 when unknown (no /proc, or the process has gone).
inline std::uint64_t residentBytes(pid_t pid = ::getpid()) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string key;
  while (in >> key) {
    if (key == "VmRSS:") {
      std::uint64_t kb = 0;
      in >> kb;
      return kb * 1024;
    }
    in.ignore(1 << 12, '\n');
  }
  return 0;
}

}  // namespace edgeslam
