#pragma once
// Runs the built `edgeslam` binary as a user would and captures what it prints.
#include <sys/wait.h>

#include <array>
#include <cstdio>
#include <string>

#include "support/shared_data.h"

namespace edgeslam::test {

struct CommandResult {
  int exit_code = -1;
  std::string output;
};

// `arguments` are appended to the binary's path; by default stderr is merged into the output, so
// append "2>/dev/null" to capture stdout only.
inline CommandResult runEdgeslam(const std::string& arguments, bool merge_stderr = true) {
  const std::string command =
      edgeslamBinary().string() + " " + arguments + (merge_stderr ? " 2>&1" : "");
  CommandResult result;
  FILE* pipe = popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  std::array<char, 4096> buffer{};
  while (const std::size_t n = fread(buffer.data(), 1, buffer.size(), pipe)) {
    result.output.append(buffer.data(), n);
  }
  const int status = pclose(pipe);
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

}  // namespace edgeslam::test
