#pragma once
// An empty folder path of the test's own: edgeslam_NAME_PID under the system's temporary folder,
// removed first if a previous run left it (not created: commands under test create what they need).
#include <unistd.h>

#include <filesystem>
#include <string>

namespace edgeslam::test {

inline std::filesystem::path freshTempDir(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() /
                   ("edgeslam_" + name + "_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

}  // namespace edgeslam::test
