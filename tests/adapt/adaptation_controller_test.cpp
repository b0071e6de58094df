#include "adapt/adaptation_controller.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <random>

#include "linkem/link_settings.h"

namespace edgeslam {
namespace {

TEST(AdaptationController, StartsWithThePaperDefaults) {
  AdaptationController controller;
  EXPECT_EQ(controller.row(), kDefaultAdaptationRow);
  EXPECT_EQ(controller.config(), KeyframeConfig{});
  EXPECT_FALSE(controller.lastNetworkTimeMs());
}

struct LinkCase {
  double rtt_ms;
  double mbps;
  double message_bytes;
  std::size_t expected_row;
};

TEST(AdaptationController, PicksTheRowOfNFromProbes) {
  // N = L + M/B: 4 + 100 kB / 200 Mbit/s = 8 ms; 6 + 8 = 14; 14 + 16 = 30; 30 + 16 = 46;
  // 55 + 100 = 155; 100 + 400 = 500.
  const LinkCase cases[] = {{4.0, 200.0, 100e3, 0}, {6.0, 100.0, 100e3, 1}, {14.0, 50.0, 100e3, 2},
                            {30.0, 50.0, 100e3, 3}, {55.0, 8.0, 100e3, 4},  {100.0, 2.0, 100e3, 4}};
  for (const LinkCase& c : cases) {
    AdaptationOptions options;
    options.message_bytes = c.message_bytes;
    AdaptationController controller(options);
    controller.onLatencyProbe(c.rtt_ms, 300);
    EXPECT_EQ(controller.row(), kDefaultAdaptationRow);  // no bandwidth yet
    const std::size_t bytes = 25000;
    const double elapsed = c.rtt_ms + bytes * 8.0 / (c.mbps * 1e3);
    controller.onBandwidthProbe(bytes, elapsed, bytes + 400);
    EXPECT_EQ(controller.row(), kDefaultAdaptationRow);  // one latency sample is not enough
    controller.onLatencyProbe(c.rtt_ms, 300);
    controller.onLatencyProbe(c.rtt_ms, 300);
    EXPECT_EQ(controller.row(), kDefaultAdaptationRow);  // nor one bandwidth sample
    controller.onBandwidthProbe(bytes, elapsed, bytes + 400);
    EXPECT_EQ(controller.row(), c.expected_row) << "rtt " << c.rtt_ms << " B " << c.mbps;
    EXPECT_EQ(controller.config(), adaptationTable()[c.expected_row].config);
    EXPECT_EQ(controller.probeBytes(), 3 * 300u + 2 * (bytes + 400u));
  }
}

TEST(AdaptationController, DoesNotFlapAroundABoundary) {
  AdaptationController controller;
  std::mt19937 random(5);
  std::normal_distribution<double> noise(0.0, 1.5);  // about +-3 ms
  std::uniform_real_distribution<double> uniform(-3.0, 3.0);
  for (int i = 0; i < 200; ++i) controller.observe(35.0 + noise(random));
  for (int i = 0; i < 200; ++i) controller.observe(35.0 + uniform(random));
  std::printf("[ measured ] switches with hysteresis over 400 noisy estimates: %llu\n",
              static_cast<unsigned long long>(controller.switches()));
  EXPECT_LE(controller.switches(), 2u);
  // The same noise without hysteresis would switch on about half of the estimates.
  AdaptationOptions eager;
  eager.margin_fraction = 0.0;
  eager.min_margin_ms = 0.0;
  eager.confirm_count = 1;
  AdaptationController flappy(eager);
  for (int i = 0; i < 200; ++i) flappy.observe(35.0 + uniform(random));
  std::printf("[ measured ] switches without hysteresis over 200 estimates: %llu\n",
              static_cast<unsigned long long>(flappy.switches()));
  EXPECT_GT(flappy.switches(), 50u);
}

TEST(AdaptationController, FollowsALastingChangeAfterConfirmation) {
  AdaptationController controller;
  controller.observe(8.0);
  EXPECT_EQ(controller.row(), 0u);
  EXPECT_EQ(controller.switches(), 1u);  // from the defaults to row 0
  EXPECT_FALSE(controller.observe(120.0));
  EXPECT_FALSE(controller.observe(120.0));
  EXPECT_EQ(controller.row(), 0u);
  EXPECT_TRUE(controller.observe(120.0));
  EXPECT_EQ(controller.row(), 4u);  // jumps straight to the row that holds N
  // Back down just inside the margin (50 - 5 ms) stays; below it moves.
  for (int i = 0; i < 5; ++i) controller.observe(46.0);
  EXPECT_EQ(controller.row(), 4u);
  for (int i = 0; i < 3; ++i) controller.observe(40.0);
  EXPECT_EQ(controller.row(), 3u);
  EXPECT_EQ(controller.switches(), 3u);
  // An interrupted excursion does not count.
  controller.observe(70.0);
  controller.observe(70.0);
  controller.observe(45.0);
  controller.observe(70.0);
  controller.observe(70.0);
  EXPECT_EQ(controller.row(), 3u);
}

TEST(AdaptationController, ASlowFirstProbeDoesNotPickTheRow) {
  // The first probe also opens the connection: 57 ms on a link whose RTT is 44 ms. Had it picked
  // configuration 5, N = 47 ms would stay inside that row's hysteresis margin (50 - 5 ms) for good.
  AdaptationOptions options;
  options.message_bytes = 5000.0;
  AdaptationController controller(options);
  const std::size_t bytes = 40000;
  const double bandwidth_mbps = 16.0;
  controller.onLatencyProbe(57.0, 100);
  controller.onBandwidthProbe(bytes, 44.0 + bytes * 8.0 / (bandwidth_mbps * 1e3), bytes);
  controller.onLatencyProbe(44.0, 100);
  EXPECT_EQ(controller.switches(), 0u);
  controller.onLatencyProbe(44.5, 100);
  EXPECT_EQ(controller.switches(), 0u);  // one bandwidth sample
  controller.onBandwidthProbe(bytes, 44.0 + bytes * 8.0 / (bandwidth_mbps * 1e3), bytes);
  EXPECT_EQ(controller.row(), 3u) << "N = " << controller.lastNetworkTimeMs().value_or(-1.0);
  EXPECT_EQ(controller.switches(), 1u);
}

TEST(AdaptationController, ASlowFirstSizedProbeDoesNotPickTheRow) {
  // Loopback (1 ms) to an edge busy with a new map's first keyframes: the first 4 KiB probe waits
  // 5 ms for the edge's CPU (B 8 Mbit/s, N 58 ms: configuration 5 on its own); the second one is
  // on time.
  AdaptationOptions options;
  options.message_bytes = 57000.0;
  AdaptationController controller(options);
  for (int i = 0; i < 3; ++i) controller.onLatencyProbe(1.0, 100);
  controller.onBandwidthProbe(4096, 5.0, 4500);
  EXPECT_EQ(controller.switches(), 0u);
  controller.onBandwidthProbe(4096, 1.0, 4500);
  EXPECT_EQ(controller.row(), 0u) << "N = " << controller.lastNetworkTimeMs().value_or(-1.0);
}

TEST(AdaptationController, CountsFramesPerConfiguration) {
  AdaptationController controller;
  controller.onFrame();
  controller.observe(5.0);
  controller.onFrame();
  controller.onFrame();
  const auto frames = controller.framesPerConfig();
  EXPECT_EQ(frames[kDefaultAdaptationRow], 1u);
  EXPECT_EQ(frames[0], 2u);
  EXPECT_EQ(frames[4], 0u);
}

TEST(AdaptationController, RejectsBadOptions) {
  AdaptationOptions options;
  options.initial_row = 5;
  EXPECT_THROW(AdaptationController{options}, std::invalid_argument);
  options = {};
  options.confirm_count = 0;
  EXPECT_THROW(AdaptationController{options}, std::invalid_argument);
  options = {};
  options.first_estimate_latency_samples = options.estimator_window + 1;
  EXPECT_THROW(AdaptationController{options}, std::invalid_argument);
  options = {};
  options.first_estimate_bandwidth_samples = options.estimator_window + 1;
  EXPECT_THROW(AdaptationController{options}, std::invalid_argument);
  AdaptationController controller;
  EXPECT_THROW(controller.setMessageBytes(-1.0), std::invalid_argument);
}

TEST(AdaptationController, LinkProfilesLandInTheExpectedRows) {
  // With M = 100 kB and L = the profile's base RTT, B = its uplink: wifi5 9 ms -> configuration
  // 1, wifi24 30 ms -> 3, lte 155 ms and lte-congested 520 ms -> 5 (docs/links.md).
  const auto rowOf = [](const char* name) {
    const LinkSettings s = linkProfile(name);
    return adaptationRowFor(networkTimeMs(s.baseRttMs(), s.up_mbps, 100e3));
  };
  EXPECT_EQ(rowOf("wifi5"), 0u);
  EXPECT_EQ(rowOf("wifi24"), 2u);
  EXPECT_EQ(rowOf("lte"), 4u);
  EXPECT_EQ(rowOf("lte-congested"), 4u);
}

}  // namespace
}  // namespace edgeslam
