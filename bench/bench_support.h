#pragma once
// Shared helpers of the micro-benchmarks: where the real data lives (EDGESLAM_SHARED overrides the
// built-in default, as for the tests).
#include <cstdlib>
#include <filesystem>
#include <string>

namespace edgeslam::bench {

inline std::filesystem::path sharedPath(const std::string& relative) {
  if (const char* env = std::getenv("EDGESLAM_SHARED"); env != nullptr && *env != '\0') {
    return std::filesystem::path(env) / relative;
  }
  return std::filesystem::path(EDGESLAM_DEFAULT_SHARED_DIR) / relative;
}

}  // namespace edgeslam::bench
