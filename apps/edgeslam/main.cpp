// `edgeslam`: one binary, one sub-command per job (run, eval, dataset, ...).
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdlib>
#include <exception>
#include <iostream>
#include <opencv2/core/utils/logger.hpp>
#include <string>

#include "commands.h"
#include "huge_page_heap.h"

namespace edgeslam::cli {

int& exitCode() {
  static int code = 0;
  return code;
}

std::string oneLine(std::string message) {
  std::replace_if(
      message.begin(), message.end(), [](char c) { return c == '\n' || c == '\r'; }, ' ');
  while (!message.empty() && message.back() == ' ') message.pop_back();
  return message;
}

std::vector<RegisteredCommand>& registeredCommands() {
  static std::vector<RegisteredCommand> commands;
  return commands;
}

}  // namespace edgeslam::cli

namespace {

// gRPC, OpenCV and FFmpeg print their own diagnostics on stderr for what edgeslam reports itself
// in one line; they stay quiet unless asked for (--log-level debug or trace, or the libraries'
// own variables, which win).
void quietLibraries(int argc, char** argv) {
  for (int i = 1; i + 1 < argc; ++i) {
    const std::string option = argv[i];
    const std::string value = argv[i + 1];
    if (option == "--log-level" && (value == "debug" || value == "trace")) return;
  }
  setenv("GRPC_VERBOSITY", "NONE", /*overwrite=*/0);
  setenv("OPENCV_FFMPEG_LOGLEVEL", "-8", 0);  // AV_LOG_QUIET
  if (std::getenv("OPENCV_LOG_LEVEL") == nullptr) {
    cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT);
  }
}

}  // namespace

int main(int argc, char** argv) {
  edgeslam::cli::restartWithHugePageHeap(argv);
  quietLibraries(argc, argv);
  CLI::App app{
      "edgeslam: edge-assisted real-time semantic visual SLAM.\n"
      "Run `edgeslam SUBCOMMAND --help` for the options of each sub-command."};
  app.require_subcommand(1);
  std::string log_level = "info";
  app.add_option("--log-level", log_level, "trace|debug|info|warn|error|off")
      ->check(CLI::IsMember({"trace", "debug", "info", "warn", "error", "off"}));
  app.set_version_flag("--version", std::string("edgeslam 0.1.0"));
  app.parse_complete_callback([&] { spdlog::set_level(spdlog::level::from_str(log_level)); });
  spdlog::set_pattern("[%H:%M:%S.%e] [%^%l%$] %v");

  auto commands = edgeslam::cli::registeredCommands();
  std::stable_sort(commands.begin(), commands.end(),
                   [](const auto& a, const auto& b) { return a.rank < b.rank; });
  for (const auto& command : commands) command.add(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::Success& e) {
    return app.exit(e);  // --help, --version
  } catch (const CLI::ParseError& e) {
    // Every usage error (unknown option, failed check, contradictory flags) exits with the same
    // code, whatever CLI11's own code for its kind; one line, so that scripts can show it.
    std::cerr << "edgeslam: usage error: " << edgeslam::cli::oneLine(e.what())
              << " (see edgeslam --help)" << std::endl;
    return edgeslam::cli::kUsageExitCode;
  } catch (const std::exception& e) {
    std::cerr << "edgeslam: error: " << edgeslam::cli::oneLine(e.what()) << std::endl;
    return edgeslam::cli::kRuntimeExitCode;
  }
  return edgeslam::cli::exitCode();
}
