#include "linkem/link_direction_model.h"

#include <gtest/gtest.h>

namespace edgeslam {
namespace {

double msSince(LinkClock::time_point t0, LinkClock::time_point t) {
  return std::chrono::duration<double, std::milli>(t - t0).count();
}

TEST(LinkDirectionModel, SerialisesAtTheRateThenAddsTheDelay) {
  LinkDirectionModel model(1);
  LinkDirectionParams p;
  p.mbps = 20.0;
  p.delay_ms = 15.0;
  const auto t0 = LinkClock::now();
  const auto segments = model.schedule(10 * 1400 + 100, t0, p);
  ASSERT_EQ(segments.size(), 11u);
  EXPECT_EQ(segments.back().bytes, 100u);
  // 1400 B at 20 Mbit/s = 0.56 ms each.
  EXPECT_NEAR(msSince(t0, segments[0].deliver_at), 15.0 + 0.56, 1e-6);
  EXPECT_NEAR(msSince(t0, segments[9].deliver_at), 15.0 + 5.6, 1e-6);
  EXPECT_NEAR(msSince(t0, segments[10].deliver_at), 15.0 + 5.6 + 0.04, 1e-6);
  // A later burst queues behind the first one.
  const auto more = model.schedule(1400, t0 + std::chrono::milliseconds(1), p);
  EXPECT_NEAR(msSince(t0, more[0].deliver_at), 15.0 + 5.64 + 0.56, 1e-6);
}

TEST(LinkDirectionModel, UnlimitedRateOnlyDelays) {
  LinkDirectionModel model(1);
  LinkDirectionParams p;
  p.delay_ms = 7.0;
  const auto t0 = LinkClock::now();
  for (const auto& s : model.schedule(100000, t0, p)) {
    EXPECT_NEAR(msSince(t0, s.deliver_at), 7.0, 1e-6);
  }
}

TEST(LinkDirectionModel, JitterAddsBoundedDelayAndKeepsOrder) {
  LinkDirectionModel model(42);
  LinkDirectionParams p;
  p.delay_ms = 10.0;
  p.jitter_ms = 8.0;
  const auto t0 = LinkClock::now();
  double lowest = 1e9;
  LinkClock::time_point previous{};
  for (int burst = 0; burst < 200; ++burst) {
    const auto now = t0 + std::chrono::milliseconds(5 * burst);
    const auto segments = model.schedule(1400, now, p);
    ASSERT_EQ(segments.size(), 1u);
    const double delay = msSince(now, segments[0].deliver_at);
    lowest = std::min(lowest, delay);
    EXPECT_GE(delay, 10.0 - 1e-9);
    EXPECT_LE(delay, 10.0 + 8.0 + 5.0);  // jitter plus at most one burst of head-of-line wait
    EXPECT_GE(segments[0].deliver_at, previous);
    previous = segments[0].deliver_at;
  }
  EXPECT_LT(lowest, 11.0);
}

TEST(LinkDirectionModel, LossCostsARetransmission) {
  LinkDirectionModel model(7);
  LinkDirectionParams p;
  p.delay_ms = 10.0;
  p.rtt_ms = 20.0;
  p.loss = 0.999999;
  const auto t0 = LinkClock::now();
  // A burst of 5: the first two have three followers (fast retransmit: +1 RTT), the tail ones
  // wait for the loss probe (+2 RTT).
  const auto burst = model.schedule(5 * 1400, t0, p);
  ASSERT_EQ(burst.size(), 5u);
  EXPECT_TRUE(burst[0].lost);
  EXPECT_NEAR(msSince(t0, burst[0].deliver_at), 10.0 + 20.0, 1e-6);
  EXPECT_NEAR(msSince(t0, burst[4].deliver_at), 10.0 + 40.0, 1e-6);
  LinkDirectionModel rare(7);
  p.loss = 0.01;
  int lost = 0;
  for (int i = 0; i < 200; ++i) {
    for (const auto& s : rare.schedule(14000, t0, p)) lost += s.lost ? 1 : 0;
  }
  EXPECT_GT(lost, 5);  // about 20 of 2000
  EXPECT_LT(lost, 45);
}

}  // namespace
}  // namespace edgeslam
