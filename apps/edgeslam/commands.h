#pragma once
// Each sub-command registers itself on the root app; the callback runs the command and sets the
// exit code.
#include <CLI/CLI.hpp>

namespace edgeslam::cli {

// Exit code of the sub-command that ran (0 when none ran yet).
int& exitCode();

void addRunCommand(CLI::App& app);
void addEvalCommands(CLI::App& app);
void addDatasetCommands(CLI::App& app);

}  // namespace edgeslam::cli
