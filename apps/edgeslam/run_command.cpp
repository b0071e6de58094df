#include "commands.h"

namespace edgeslam::cli {

void addRunCommand(CLI::App& app) {
  app.add_subcommand("run", "Run SLAM on a dataset (client and edge in one command)");
}

}  // namespace edgeslam::cli
