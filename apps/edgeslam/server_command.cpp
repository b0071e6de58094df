// `edgeslam server`: the edge alone, serving any number of client sessions until interrupted.
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <memory>
#include <thread>

#include "commands.h"
#include "pipeline/slam_session_backend.h"
#include "vocabulary_option.h"

namespace edgeslam::cli {
namespace {

std::atomic<bool> g_stop{false};

void requestStop(int) {
  g_stop = true;
}

int runServer(const std::string& listen, int status_interval_s, const std::string& vocabulary) {
  SlamSessionOptions options;
  options.mapping.vocabulary = loadVocabulary(vocabulary);
  EdgeServer server(listen, std::make_shared<SlamSessionFactory>(options));
  spdlog::info("edge server listening on {} (Ctrl-C to stop)", server.address());
  std::signal(SIGINT, requestStop);
  std::signal(SIGTERM, requestStop);
  auto last_status = std::chrono::steady_clock::now();
  while (!g_stop) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    if (status_interval_s > 0 &&
        std::chrono::steady_clock::now() - last_status > std::chrono::seconds(status_interval_s)) {
      last_status = std::chrono::steady_clock::now();
      for (const SessionStats& s : server.sessions()) {
        spdlog::info("session {} '{}': {} keyframes, {} frames, {} slices, {} B up, {} B down",
                     s.session_id, s.client_name, s.keyframes, s.frames, s.slices_sent,
                     s.uplink_bytes, s.downlink_bytes);
      }
    }
  }
  spdlog::info("stopping: {} session(s) open", server.sessionCount());
  server.shutdown();
  return 0;
}

void addServerCommand(CLI::App& app) {
  auto listen = std::make_shared<std::string>("0.0.0.0:50051");
  auto interval = std::make_shared<int>(10);
  auto vocabulary = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("server", "The edge server: global maps for many client sessions");
  cmd->add_option("--listen", *listen, "HOST:PORT to listen on (port 0 = any free port)");
  cmd->add_option("--status-every", *interval, "Seconds between session status lines (0 = none)");
  cmd->add_option("--vocab", *vocabulary,
                  "Vocabulary for loop closing (default: vocab/ next to the binary; none = off)");
  cmd->callback(
      [listen, interval, vocabulary] { exitCode() = runServer(*listen, *interval, *vocabulary); });
}

const CommandRegistration kServerCommandRegistration{15, addServerCommand};

}  // namespace
}  // namespace edgeslam::cli
