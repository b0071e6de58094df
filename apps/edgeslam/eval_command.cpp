#include "commands.h"

namespace edgeslam::cli {

void addEvalCommands(CLI::App& app) {
  auto* eval = app.add_subcommand("eval", "Evaluate an estimated trajectory against ground truth");
  eval->require_subcommand(1);
}

}  // namespace edgeslam::cli
