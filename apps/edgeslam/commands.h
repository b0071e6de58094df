#pragma once
// Each sub-command file registers itself with a `CommandRegistration` at namespace scope; main()
// adds every registered command to the root app in the order of their `rank`. The callback of a
// command runs it and sets the exit code.
#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace edgeslam::cli {

// Exit code of the sub-command that ran (0 when none ran yet).
int& exitCode();

// Exit codes of every command: 2 for a wrong command line (throw a CLI::ValidationError from a
// callback for flags that contradict each other), 1 for a failure while running.
inline constexpr int kUsageExitCode = 2;
inline constexpr int kRuntimeExitCode = 1;

// `message` with its line breaks replaced by spaces: every error is one line.
std::string oneLine(std::string message);

using AddCommand = std::function<void(CLI::App&)>;

struct RegisteredCommand {
  int rank = 0;  // position in `edgeslam --help`: lower first
  AddCommand add;
};

std::vector<RegisteredCommand>& registeredCommands();

struct CommandRegistration {
  CommandRegistration(int rank, AddCommand add) {
    registeredCommands().push_back({rank, std::move(add)});
  }
};

}  // namespace edgeslam::cli
