// `edgeslam linkem`: a TCP proxy that emulates a wireless link (delay, jitter, bandwidth, loss)
// between clients and a server, e.g. between `edgeslam client` and `edgeslam server`.
#include <fmt/format.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <thread>

#include "commands.h"
#include "linkem/link_emulator.h"

namespace edgeslam::cli {
namespace {

struct LinkemOptions {
  std::string listen;
  std::string target;
  std::string profile;
  std::optional<double> delay_ms;
  std::optional<double> delay_up_ms;
  std::optional<double> delay_down_ms;
  std::optional<double> jitter_ms;
  std::optional<double> up_mbps;
  std::optional<double> down_mbps;
  std::optional<double> loss;
  std::string trace;
  double interval_s = 1.0;
  std::uint64_t seed = 0;
};

volatile std::sig_atomic_t g_stop_signal = 0;

extern "C" void onStopSignal(int signal) {
  g_stop_signal = signal;
}

// Restores the previous handlers when the command ends.
class StopSignals {
 public:
  StopSignals() {
    g_stop_signal = 0;
    previous_int_ = std::signal(SIGINT, onStopSignal);
    previous_term_ = std::signal(SIGTERM, onStopSignal);
  }
  ~StopSignals() {
    std::signal(SIGINT, previous_int_);
    std::signal(SIGTERM, previous_term_);
  }
  StopSignals(const StopSignals&) = delete;
  StopSignals& operator=(const StopSignals&) = delete;
  bool raised() const { return g_stop_signal != 0; }

 private:
  void (*previous_int_)(int) = SIG_DFL;
  void (*previous_term_)(int) = SIG_DFL;
};

LinkSettings settingsFrom(const LinkemOptions& o) {
  LinkSettings s = o.profile.empty() ? LinkSettings{} : linkProfile(o.profile);
  if (o.delay_ms) s.delay_up_ms = s.delay_down_ms = *o.delay_ms;
  if (o.delay_up_ms) s.delay_up_ms = *o.delay_up_ms;
  if (o.delay_down_ms) s.delay_down_ms = *o.delay_down_ms;
  if (o.jitter_ms) s.jitter_ms = *o.jitter_ms;
  if (o.up_mbps) s.up_mbps = *o.up_mbps;
  if (o.down_mbps) s.down_mbps = *o.down_mbps;
  if (o.loss) s.loss = *o.loss;
  validate(s);
  return s;
}

void runLinkem(const LinkemOptions& o) {
  LinkEmulatorOptions options;
  options.listen = parseHostPort(o.listen);
  options.target = parseHostPort(o.target);
  options.settings = settingsFrom(o);
  options.seed = o.seed;
  if (!o.trace.empty()) options.trace = LinkTrace::load(o.trace);
  const std::optional<LinkTrace> trace = options.trace;
  const LinkSettings base = options.settings;

  StopSignals signals;
  LinkEmulator emulator(std::move(options));
  emulator.start();
  fmt::print("linkem: {}:{} -> {}\n", o.listen.substr(0, o.listen.rfind(':')), emulator.port(),
             o.target);
  fmt::print("linkem: {}{}\n", o.profile.empty() ? "" : fmt::format("profile {}: ", o.profile),
             base.describe());
  if (trace) {
    fmt::print("linkem: replaying trace {} ({} points, period {:g} s, looping)\n", o.trace,
               trace->points().size(), trace->periodS());
  }
  std::fflush(stdout);

  using Clock = std::chrono::steady_clock;
  const auto period = std::chrono::duration<double>(o.interval_s);
  auto last_time = Clock::now();
  LinkStats last = emulator.stats();
  while (!signals.raised()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    const auto now = Clock::now();
    if (now - last_time < period) continue;
    const LinkStats stats = emulator.stats();
    const double seconds = std::chrono::duration<double>(now - last_time).count();
    const auto mbps = [&](std::uint64_t bytes, std::uint64_t before) {
      return static_cast<double>(bytes - before) * 8.0 / seconds / 1e6;
    };
    fmt::print("up {:8.3f} Mbit/s  down {:8.3f} Mbit/s  connections {} active, {} total{}{}\n",
               mbps(stats.bytes_up, last.bytes_up), mbps(stats.bytes_down, last.bytes_down),
               stats.connections_active, stats.connections_total,
               stats.lost_segments > 0 ? fmt::format("  lost segments {}", stats.lost_segments)
                                       : std::string(),
               trace ? fmt::format("  [trace: up {:g} down {:g} Mbit/s]",
                                   emulator.currentSettings().up_mbps,
                                   emulator.currentSettings().down_mbps)
                     : std::string());
    std::fflush(stdout);
    last = stats;
    last_time = now;
  }
  emulator.stop();
  const LinkStats total = emulator.stats();
  fmt::print("linkem: stopped; {} bytes up, {} bytes down, {} connections\n", total.bytes_up,
             total.bytes_down, total.connections_total);
}

}  // namespace

void addLinkemCommand(CLI::App& app) {
  auto o = std::make_shared<LinkemOptions>();
  auto* cmd = app.add_subcommand(
      "linkem",
      "Link emulator: a TCP proxy adding delay, jitter, bandwidth limits and TCP-felt loss "
      "between clients and a server (\"up\" = client -> server). Runs until SIGINT/SIGTERM. "
      "Model, profiles and trace format: docs/links.md");
  cmd->add_option("--listen", o->listen, "HOST:PORT to accept clients on (port 0: any free port)")
      ->required();
  cmd->add_option("--target", o->target, "HOST:PORT of the server to forward to")->required();
  std::string profiles;
  for (const auto& name : linkProfileNames()) profiles += (profiles.empty() ? "" : "|") + name;
  cmd->add_option("--profile", o->profile,
                  "Named link (" + profiles + "); the flags below override its values")
      ->check(CLI::IsMember(linkProfileNames()));
  cmd->add_option("--delay-ms", o->delay_ms, "One-way delay each direction (ms)");
  cmd->add_option("--delay-up-ms", o->delay_up_ms, "One-way delay client -> server (ms)");
  cmd->add_option("--delay-down-ms", o->delay_down_ms, "One-way delay server -> client (ms)");
  cmd->add_option("--jitter-ms", o->jitter_ms,
                  "Random extra delay per segment, uniform in [0, J] (ms); order is kept");
  cmd->add_option("--up-mbps", o->up_mbps, "Bandwidth client -> server (Mbit/s, 0 = unlimited)");
  cmd->add_option("--down-mbps", o->down_mbps,
                  "Bandwidth server -> client (Mbit/s, 0 = unlimited)");
  cmd->add_option("--loss", o->loss,
                  "Probability that a ~1400-byte segment is lost and retransmitted (0..1)");
  cmd->add_option("--trace", o->trace,
                  "Trace file replayed in a loop: lines 'time_s up_mbps down_mbps delay_up_ms "
                  "delay_down_ms [jitter_ms [loss]]'");
  cmd->add_option("--interval", o->interval_s, "Seconds between throughput lines")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the jitter and loss draws (0 = random)");
  cmd->callback([o] {
    try {
      runLinkem(*o);
      exitCode() = 0;
    } catch (const CLI::Error&) {
      throw;  // a usage error: main() reports it
    } catch (const std::exception& e) {
      std::cerr << "edgeslam linkem: error: " << e.what() << std::endl;
      exitCode() = 1;
    }
  });
}

const CommandRegistration kLinkemCommandRegistration{80, addLinkemCommand};

}  // namespace edgeslam::cli
