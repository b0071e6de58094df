#pragma once
// Locates the shared real data (../shared) for tests; EDGESLAM_SHARED overrides the built-in
// default.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

namespace edgeslam::test {

inline std::filesystem::path sharedDir() {
  if (const char* env = std::getenv("EDGESLAM_SHARED"); env != nullptr && *env != '\0') {
    return env;
  }
  return EDGESLAM_DEFAULT_SHARED_DIR;
}

inline std::filesystem::path sharedPath(const std::string& relative) {
  return sharedDir() / relative;
}

inline std::filesystem::path edgeslamBinary() {
  return EDGESLAM_BINARY_PATH;
}

}  // namespace edgeslam::test

// Skips the current test with a clear message when a shared file or folder is absent.
#define EDGESLAM_REQUIRE_SHARED(relative)                                                   \
  do {                                                                                      \
    const auto required_path_ = ::edgeslam::test::sharedPath(relative);                     \
    if (!std::filesystem::exists(required_path_)) {                                         \
      GTEST_SKIP() << "shared data not found: " << required_path_                           \
                   << " (set EDGESLAM_SHARED to the folder holding datasets/ and models/)"; \
    }                                                                                       \
  } while (0)
