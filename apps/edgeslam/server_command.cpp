// `edgeslam server`: the edge alone, serving any number of client sessions until interrupted.
#include <spdlog/spdlog.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <filesystem>
#include <memory>
#include <optional>
#include <thread>

#include "commands.h"
#include "map_store_option.h"
#include "modes/slam_session_backend.h"
#include "network_security_options.h"
#include "segmenter_option.h"
#include "server_metrics.h"
#include "server_viewer.h"
#include "vocabulary_option.h"

namespace edgeslam::cli {
namespace {

std::atomic<bool> g_stop{false};

void requestStop(int) {
  g_stop = true;
}

struct ServerOptions {
  std::string listen = "127.0.0.1:50051";
  int status_interval_s = 10;
  std::string vocabulary;
  std::string semantic = "auto";
  std::filesystem::path models_dir;
  int segment_input = 256;
  std::string maps;
  ServerSecurityOptions security;
  std::optional<int> viewer_port;
  std::string viewer_host = "127.0.0.1";
  int idle_timeout_s = 60;
  std::filesystem::path metrics;
};

int runServer(const ServerOptions& o) {
  // First: a server that would be open to the network does not start at all.
  EdgeServerSecurity security = loadServerSecurity(o.security, o.listen);
  std::unique_ptr<ServerViewer> viewer;
  if (o.viewer_port) viewer = std::make_unique<ServerViewer>(o.viewer_host, *o.viewer_port);
  SlamSessionOptions options;
  options.mapping.backend.vocabulary = loadVocabulary(o.vocabulary);
  if (o.semantic != "off") {
    const SegmenterOptions segmenter = segmenterOptions(o.models_dir, o.segment_input);
    try {
      loadSegmenter(segmenter);  // fail now rather than at the first session
      options.segmenter = segmenter;
      spdlog::info("segmentation models in {}: sessions may ask for semantic culling",
                   segmenter.model_dir.string());
    } catch (const std::exception& e) {
      if (o.semantic == "on") throw;
      spdlog::warn("no segmentation ({}): sessions asking for semantic culling are refused",
                   e.what());
    }
  }
  const MapStoreChoice store = openStoreForWriting(o.maps);
  options.store = store.store;
  options.store_stats = store.stats;
  if (store.store) {
    for (const MapSummary& map : store.store->listMaps()) {
      spdlog::info("map '{}': {} keyframes, {} points, {} session(s)", map.name, map.keyframes,
                   map.points, map.sessions);
    }
  }
  const std::string& listen = o.listen;
  const int status_interval_s = o.status_interval_s;
  std::shared_ptr<EdgeSessionFactory> factory = std::make_shared<SlamSessionFactory>(options);
  if (viewer) {
    factory = viewer->wrap(std::move(factory));
    if (store.store) viewer->showStore(store.store);
  }
  EdgeServerLimits limits = serverLimits(o.security);
  limits.idle_timeout = std::chrono::seconds(o.idle_timeout_s);
  EdgeServer server(listen, std::move(factory), limits, std::move(security));
  const auto started = std::chrono::steady_clock::now();
  const auto write_metrics = [&] {
    if (o.metrics.empty()) return;
    const double uptime_s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    try {
      writeServerMetrics(o.metrics, serverMetricsJson(server, uptime_s, store.stats.get()));
    } catch (const std::exception& e) {
      spdlog::warn("server metrics: {}", e.what());
    }
  };
  const auto viewer_attachment = viewer ? viewer->attach(server) : nullptr;
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
      write_metrics();
    }
  }
  spdlog::info("stopping: {} session(s) open", server.sessionCount());
  server.shutdown();
  const ClosedSessionTotals closed = server.closedSessions();
  spdlog::info(
      "closed sessions: {} ({} by their client, {} idle, {} reclaimed, {} at shutdown, {} failed); "
      "{} keyframes received, {} uploads missing; {} of {} slices never acknowledged",
      closed.sessions, closed.closed_by_client, closed.closed_idle, closed.closed_reclaimed,
      closed.closed_at_shutdown, closed.closed_failed, closed.keyframes, closed.missing_uploads,
      closed.slices_unacknowledged, closed.slices_pushed);
  write_metrics();
  return 0;
}

void addServerCommand(CLI::App& app) {
  auto o = std::make_shared<ServerOptions>();
  auto* cmd = app.add_subcommand("server", "The edge server: global maps for many client sessions");
  cmd->add_option("--listen", o->listen,
                  "HOST:PORT to listen on (port 0 = any free port); an address off loopback needs "
                  "--tls-cert, --tls-key and --auth-tokens, or --insecure")
      ->check(listenAddress())
      ->capture_default_str();
  cmd->add_option("--status-every", o->status_interval_s,
                  "Seconds between session status lines (0 = none)");
  cmd->add_option("--vocab", o->vocabulary,
                  "Vocabulary for loop closing (default: vocab/ next to the binary; none = off)");
  cmd->add_option("--semantic", o->semantic,
                  "Segment keyframes for clients that ask: on (models required), off, auto (when "
                  "the models load)")
      ->check(CLI::IsMember({"on", "off", "auto"}));
  cmd->add_option("--segment-input", o->segment_input,
                  "Side of the segmentation detector's input (multiple of 32)")
      ->capture_default_str();
  cmd->add_option("--models", o->models_dir,
                  "Segmentation models folder (default: the shared models)");
  addMapsOption(cmd, o->maps);
  cmd->add_option("--idle-timeout", o->idle_timeout_s,
                  "Seconds without a request or an open slice stream after which a session is "
                  "closed (its client vanished)")
      ->check(CLI::Range(1, 86400))
      ->capture_default_str();
  cmd->add_option("--metrics", o->metrics,
                  "Write the server's metrics (sessions, what closed sessions lost, RSS) as JSON "
                  "to this file at every status line and at stop");
  addServerSecurityOptions(*cmd, o->security);
  cmd->add_option("--viewer", o->viewer_port,
                  "Serve the edge view (every session's map and figures) on this port (0 = any "
                  "free port; the URL is logged)")
      ->check(CLI::Range(0, 65535));
  cmd->add_option("--viewer-host", o->viewer_host,
                  "Address the viewer listens on (0.0.0.0 = every interface)");
  cmd->callback([o] { exitCode() = runServer(*o); });
}

const CommandRegistration kServerCommandRegistration{15, addServerCommand};

}  // namespace
}  // namespace edgeslam::cli
