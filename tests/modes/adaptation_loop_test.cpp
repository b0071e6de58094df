#include "modes/adaptation_loop.h"

#include <gtest/gtest.h>
#include <sched.h>
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "geometry/camera.h"
#include "linkem/link_emulator.h"
#include "wire/edge_client.h"
#include "wire/edge_server.h"

namespace edgeslam {
namespace {

using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// The edge side does nothing but answer probes (the server itself does that).
class IdleBackend final : public EdgeSessionBackend {
 public:
  void onKeyFrame(KeyFrameUpload /*upload*/) override {}
};

class IdleFactory final : public EdgeSessionFactory {
 public:
  std::unique_ptr<EdgeSessionBackend> open(const SessionConfig& /*config*/,
                                           SliceSink& /*sink*/) override {
    return std::make_unique<IdleBackend>();
  }
};

SessionConfig probeSessionConfig() {
  CameraIntrinsics in;
  in.width = 640;
  in.height = 480;
  in.fx = in.fy = 525.0;
  in.cx = 319.5;
  in.cy = 239.5;
  in.fps = 30.0;
  SessionConfig config;
  config.client_name = "adaptation-loop-test";
  config.camera = PinholeCamera(in);
  return config;
}

LinkSettings symmetricLink(double one_way_ms, double mbps) {
  LinkSettings settings;
  settings.delay_up_ms = settings.delay_down_ms = one_way_ms;
  settings.up_mbps = settings.down_mbps = mbps;
  return settings;
}

// Fast probing so that a test sees many samples in a few seconds; sized probes of ~20 ms so that
// their transfer time stands out of the scheduler noise of a loaded machine.
AdaptationLoopOptions fastOptions(double message_bytes) {
  AdaptationLoopOptions options;
  options.schedule.small_interval_s = 0.1;
  options.schedule.sized_interval_s = 0.25;
  options.schedule.sized_target_ms = 20.0;
  options.controller.message_bytes = message_bytes;
  options.probe_timeout = milliseconds(1000);
  options.poll_interval = milliseconds(10);
  return options;
}

template <typename Predicate>
bool eventually(Predicate predicate, milliseconds timeout) {
  const auto deadline = Clock::now() + timeout;
  while (Clock::now() < deadline) {
    if (predicate()) return true;
    std::this_thread::sleep_for(milliseconds(10));
  }
  return predicate();
}

double msSince(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// Timing on a busy machine: every probe crosses ~8 thread wake-ups (client, emulator both ways,
// server), and each can wait a CPU time slice behind other processes (the RTT median of a 40 ms
// link rose to 50-70 ms with two busy loops on the two cores). Raising this process's priority
// before its threads exist (they inherit it) keeps what is measured the emulated link: the
// lowest real-time priority (the threads mostly sleep, and the kernel caps real-time tasks at 95%
// of the CPU), else a lower nice value; where neither is permitted, normal priority.
void raisePriority() {
  static const bool raised = [] {
    sched_param param{};
    param.sched_priority = 1;
    return sched_setscheduler(0, SCHED_RR, &param) == 0 || setpriority(PRIO_PROCESS, 0, -10) == 0;
  }();
  (void)raised;
}

// A real edge server behind the link emulator, and a client connected through it.
struct LinkedEdge {
  explicit LinkedEdge(const LinkSettings& settings)
      : priority((raisePriority(), true)),
        server("127.0.0.1:0", std::make_shared<IdleFactory>()),
        emulator([&] {
          LinkEmulatorOptions options;
          options.target = {"127.0.0.1", static_cast<std::uint16_t>(server.port())};
          options.settings = settings;
          options.seed = 7;
          return options;
        }()) {
    emulator.start();
    client = std::make_unique<EdgeClient>("127.0.0.1:" + std::to_string(emulator.port()),
                                          probeSessionConfig());
  }
  ~LinkedEdge() {
    client->close();
    emulator.stop();
    server.shutdown();
  }

  bool priority;
  EdgeServer server;
  LinkEmulator emulator;
  std::unique_ptr<EdgeClient> client;
};

TEST(AdaptationLoop, MeasuresTheEmulatedLinkAndFollowsItsChanges) {
  // 20 + 20 ms, 16 Mbit/s, keyframes of 5 kB: N = 40 + 2.5 ms -> Table I row 4 (35, 50].
  LinkedEdge edge(symmetricLink(20.0, 16.0));
  AdaptationLoop loop(*edge.client, fastOptions(5000.0));
  EXPECT_EQ(loop.version(), 0u);
  EXPECT_EQ(loop.row(), kDefaultAdaptationRow);
  loop.start();
  ASSERT_TRUE(eventually(
      [&] {
        const AdaptationLoopCounters c = loop.counters();
        return c.latency_probes >= 7 && c.bandwidth_probes >= 6;
      },
      milliseconds(10000)));
  const NetworkEstimates measured = loop.estimates();
  ASSERT_TRUE(measured.latency_ms && measured.bandwidth_mbps && measured.network_time_ms);
  EXPECT_NEAR(*measured.latency_ms, 40.0, 0.15 * 40.0);
  EXPECT_NEAR(*measured.bandwidth_mbps, 16.0, 0.25 * 16.0);
  EXPECT_DOUBLE_EQ(measured.message_bytes, 5000.0);
  EXPECT_EQ(loop.row(), 3u) << "N = " << *measured.network_time_ms << " ms";
  std::printf("20+20 ms, 16 Mbit/s: L %.2f ms, B %.2f Mbit/s, N %.2f ms\n", *measured.latency_ms,
              *measured.bandwidth_mbps, *measured.network_time_ms);
  EXPECT_EQ(loop.current(), adaptationTable()[3].config);
  EXPECT_GE(loop.version(), 1u);
  EXPECT_EQ(loop.counters().failed_probes, 0u);

  // A much slower link (N > 120 ms): row 5 after a few probes.
  const std::uint64_t before_slow = loop.counters().latency_probes;
  edge.emulator.setSettings(symmetricLink(60.0, 16.0));
  ASSERT_TRUE(eventually([&] { return loop.row() == 4; }, milliseconds(6000)))
      << "N = " << loop.estimates().network_time_ms.value_or(-1.0);
  const std::uint64_t probes_to_slow = loop.counters().latency_probes - before_slow;
  EXPECT_LE(probes_to_slow, 12u);
  std::printf("60+60 ms: row 5 after %llu latency probes\n",
              static_cast<unsigned long long>(probes_to_slow));
  EXPECT_EQ(loop.current(), adaptationTable()[4].config);

  // An instant link: back to the first rows (row 1 expected; row 2 tolerated, since on a busy
  // machine the loopback round trip alone can take several ms).
  edge.emulator.setSettings(symmetricLink(1.0, 0.0));
  ASSERT_TRUE(eventually([&] { return loop.row() <= 1; }, milliseconds(6000)))
      << "N = " << loop.estimates().network_time_ms.value_or(-1.0);
  const AdaptationLoopCounters counters = loop.counters();
  EXPECT_GE(counters.switches, 3u);
  EXPECT_LE(counters.switches, 5u);  // no flapping
  EXPECT_GT(counters.probe_bytes, counters.probe_uplink_bytes);
  EXPECT_GT(counters.probe_uplink_bytes, 0u);

  const auto stop_start = Clock::now();
  loop.stop();
  EXPECT_LT(msSince(stop_start), 500.0);
  const std::uint64_t probes_after_stop = loop.counters().latency_probes;
  std::this_thread::sleep_for(milliseconds(250));
  EXPECT_EQ(loop.counters().latency_probes, probes_after_stop);
}

TEST(AdaptationLoop, AdaptOffProbesButNeverSwitches) {
  LinkedEdge edge(symmetricLink(20.0, 16.0));
  AdaptationLoopOptions options = fastOptions(5000.0);
  options.adapt = false;
  options.controller.initial_row = 0;
  AdaptationLoop loop(*edge.client, options);
  loop.start();
  for (int i = 0; i < 5; ++i) loop.onFrame();
  ASSERT_TRUE(
      eventually([&] { return loop.counters().bandwidth_probes >= 3; }, milliseconds(8000)));
  const NetworkEstimates measured = loop.estimates();
  ASSERT_TRUE(measured.network_time_ms);
  EXPECT_GT(*measured.latency_ms, 30.0);
  loop.stop();
  const AdaptationLoopCounters counters = loop.counters();
  EXPECT_EQ(loop.version(), 0u);
  EXPECT_EQ(loop.row(), 0u);
  EXPECT_EQ(loop.current(), adaptationTable()[0].config);
  EXPECT_EQ(counters.switches, 0u);
  EXPECT_EQ(counters.frames_per_config[0], 5u);
  EXPECT_GT(counters.probe_bytes, 0u);
}

TEST(AdaptationLoop, UnansweredProbesCountAsAVerySlowLink) {
  // A server that never answers: each probe waits for the timeout and counts as that long.
  AdaptationLoopOptions options = fastOptions(5000.0);
  options.schedule.small_interval_s = 0.02;
  options.schedule.sized_interval_s = 0.05;
  options.probe_timeout = milliseconds(400);
  AdaptationLoop::ProbeFunction unanswered = [](std::size_t, std::size_t, milliseconds timeout) {
    std::this_thread::sleep_for(timeout / 10);  // gRPC gives up at the deadline; keep it quick
    return std::optional<ProbeResult>();
  };
  AdaptationLoop loop(unanswered, options);
  loop.start();
  ASSERT_TRUE(eventually([&] { return loop.row() == 4; }, milliseconds(5000)))
      << "L " << loop.estimates().latency_ms.value_or(-1.0) << " B "
      << loop.estimates().bandwidth_mbps.value_or(-1.0) << " failed "
      << loop.counters().failed_probes;
  EXPECT_GE(loop.counters().failed_probes, 2u);
  EXPECT_GE(*loop.estimates().latency_ms, 400.0);
  loop.stop();
}

TEST(AdaptationLoop, AProbeTooFastToResolveIsFollowedByALargerOne) {
  // A 1 Gbit/s link with a 1 ms RTT: 4 KiB cross in 0.03 ms, below the 0.05 ms the estimator
  // resolves; the loop doubles the probe at once until one shows its transfer time (8 KiB).
  AdaptationLoopOptions options = fastOptions(5000.0);
  options.schedule.sized_target_ms = 0.01;  // sized from the estimate: the smallest, 4 KiB
  std::mutex mutex;
  std::vector<std::size_t> sizes;
  AdaptationLoop::ProbeFunction link = [&](std::size_t payload, std::size_t, milliseconds) {
    {
      std::lock_guard lock(mutex);
      sizes.push_back(payload);
    }
    ProbeResult result;
    result.round_trip_ms = 1.0 + static_cast<double>(payload) * 8.0 / 1e6;  // 1000 Mbit/s
    result.sent_bytes = payload;
    result.received_bytes = 32;
    return std::optional<ProbeResult>(result);
  };
  AdaptationLoop loop(link, options);
  loop.start();
  ASSERT_TRUE(
      eventually([&] { return loop.estimates().bandwidth_mbps.has_value(); }, milliseconds(5000)));
  loop.stop();
  EXPECT_NEAR(*loop.estimates().bandwidth_mbps, 1000.0, 10.0);
  std::lock_guard lock(mutex);
  std::vector<std::size_t> sized;
  for (const std::size_t s : sizes) {
    if (s > options.schedule.small_payload_bytes) sized.push_back(s);
  }
  ASSERT_GE(sized.size(), 2u);
  EXPECT_EQ(sized[0], 4096u);
  EXPECT_EQ(sized[1], 8192u);
}

TEST(AdaptationLoop, AProbeTooFastAtTheLargestSizeCountsAtTheBound) {
  // Loopback answers every size within the RTT: the loop climbs to 64 KiB and counts that one at
  // the resolution bound (64 KiB in 0.05 ms), so a fast link reads fast.
  AdaptationLoopOptions options = fastOptions(60000.0);
  AdaptationLoop::ProbeFunction loopback = [](std::size_t payload, std::size_t, milliseconds) {
    ProbeResult result;
    result.round_trip_ms = 1.0;
    result.sent_bytes = payload;
    result.received_bytes = 32;
    return std::optional<ProbeResult>(result);
  };
  AdaptationLoop loop(loopback, options);
  loop.start();
  ASSERT_TRUE(eventually([&] { return loop.row() == 0; }, milliseconds(5000)))
      << "N " << loop.estimates().network_time_ms.value_or(-1.0);
  loop.stop();
  EXPECT_NEAR(*loop.estimates().bandwidth_mbps, 65536 * 8.0 / 50.0, 1.0);
}

TEST(AdaptationLoop, AnOutageOfTheEdgeIsNoSampleOfTheLink) {
  // The edge goes away (a server killed and restarted, issue 19): probes fail with the channel
  // down. Taken as 1 s round trips they switched a loopback client to the slowest row for the
  // outage and ~10 s after it; they are counted apart and the configuration stays.
  auto server = std::make_unique<EdgeServer>("127.0.0.1:0", std::make_shared<IdleFactory>());
  EdgeClient client("127.0.0.1:" + std::to_string(server->port()), probeSessionConfig());
  EXPECT_TRUE(client.connected());
  AdaptationLoop loop(client, fastOptions(5000.0));
  loop.start();
  ASSERT_TRUE(eventually([&] { return loop.estimates().network_time_ms.has_value(); },
                         milliseconds(10000)));
  server->shutdown();
  server.reset();
  const std::uint64_t version = loop.version();
  const std::size_t row = loop.row();
  const double latency_ms = *loop.estimates().latency_ms;
  ASSERT_TRUE(
      eventually([&] { return loop.counters().unreachable_probes >= 8; }, milliseconds(10000)))
      << "failed " << loop.counters().failed_probes;
  EXPECT_FALSE(client.connected());
  // At most the probe in flight when the server went, failing before the channel knew.
  EXPECT_LE(loop.counters().failed_probes, 1u);
  EXPECT_EQ(loop.version(), version);
  EXPECT_EQ(loop.row(), row);
  EXPECT_LT(*loop.estimates().latency_ms, std::max(100.0, 2.0 * latency_ms));
  loop.stop();
  client.close();
}

TEST(AdaptationLoop, StopReturnsWhileAProbeIsStuck) {
  AdaptationLoopOptions options = fastOptions(5000.0);
  options.probe_timeout = milliseconds(300);
  std::atomic<int> calls{0};
  AdaptationLoop::ProbeFunction stuck = [&](std::size_t, std::size_t, milliseconds timeout) {
    ++calls;
    std::this_thread::sleep_for(timeout);  // what a deadline-bounded RPC does at worst
    return std::optional<ProbeResult>();
  };
  AdaptationLoop loop(stuck, options);
  loop.start();
  ASSERT_TRUE(eventually([&] { return calls.load() >= 1; }, milliseconds(2000)));
  const auto stop_start = Clock::now();
  loop.stop();
  EXPECT_LT(msSince(stop_start), 300.0 + 400.0);
  loop.stop();  // idempotent
}

TEST(AdaptationLoop, RefusedProbesStopProbingAndKeepTheConfiguration) {
  std::atomic<int> calls{0};
  AdaptationLoop::ProbeFunction refused = [&](std::size_t, std::size_t,
                                              milliseconds) -> std::optional<ProbeResult> {
    ++calls;
    throw EdgeClientError("probe rejected by the edge server: UNIMPLEMENTED");
  };
  AdaptationLoop loop(refused, fastOptions(5000.0));
  loop.start();
  std::this_thread::sleep_for(milliseconds(300));
  EXPECT_EQ(calls.load(), 1);
  EXPECT_EQ(loop.version(), 0u);
  EXPECT_EQ(loop.row(), kDefaultAdaptationRow);
  const auto stop_start = Clock::now();
  loop.stop();
  EXPECT_LT(msSince(stop_start), 200.0);
}

TEST(AdaptationLoop, RejectsBadSettings) {
  AdaptationLoop::ProbeFunction none;
  EXPECT_THROW(AdaptationLoop(none, AdaptationLoopOptions{}), std::invalid_argument);
  AdaptationLoopOptions options;
  options.probe_timeout = milliseconds(0);
  auto answer = [](std::size_t, std::size_t, milliseconds) { return std::optional<ProbeResult>(); };
  EXPECT_THROW(AdaptationLoop(answer, options), std::invalid_argument);
  AdaptationLoop loop(answer, AdaptationLoopOptions{});
  EXPECT_THROW(loop.setMessageBytes(-1.0), std::invalid_argument);
  loop.setMessageBytes(60e3);
  EXPECT_DOUBLE_EQ(loop.estimates().message_bytes, 60e3);
  loop.stop();   // never started: fine
  loop.start();  // after stop: stays stopped
}

}  // namespace
}  // namespace edgeslam
