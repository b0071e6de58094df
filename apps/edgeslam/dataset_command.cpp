#include "commands.h"

namespace edgeslam::cli {

void addDatasetCommands(CLI::App& app) {
  auto* dataset = app.add_subcommand("dataset", "Inspect datasets");
  dataset->require_subcommand(1);
}

}  // namespace edgeslam::cli
