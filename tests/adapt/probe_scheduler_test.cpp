#include "adapt/probe_scheduler.h"

#include <gtest/gtest.h>

namespace edgeslam {
namespace {

TEST(ProbeScheduler, SmallEverySecondSizedEveryFiveSeconds) {
  ProbeScheduler scheduler;
  EXPECT_EQ(scheduler.next(0.0), ProbeKind::kSmall);
  EXPECT_EQ(scheduler.next(0.0), ProbeKind::kSized);
  EXPECT_EQ(scheduler.next(0.0), ProbeKind::kNone);
  int small = 0;
  int sized = 0;
  // Polled every frame at 30 fps for 60 s (and a few frames: a sized probe due together with a
  // small one goes out one call later).
  for (int frame = 1; frame <= 1805; ++frame) {
    switch (scheduler.next(frame / 30.0)) {
      case ProbeKind::kSmall:
        ++small;
        break;
      case ProbeKind::kSized:
        ++sized;
        break;
      case ProbeKind::kNone:
        break;
    }
  }
  EXPECT_EQ(small, 60);
  EXPECT_EQ(sized, 12);
}

TEST(ProbeScheduler, SecondSizedProbeOneSmallIntervalAfterTheFirst) {
  ProbeScheduler scheduler;
  EXPECT_EQ(scheduler.next(0.0), ProbeKind::kSmall);
  EXPECT_EQ(scheduler.next(0.0), ProbeKind::kSized);
  EXPECT_EQ(scheduler.next(1.0), ProbeKind::kSmall);
  EXPECT_EQ(scheduler.next(1.0), ProbeKind::kSized);
  EXPECT_EQ(scheduler.next(2.0), ProbeKind::kSmall);
  EXPECT_EQ(scheduler.next(2.0), ProbeKind::kNone);
  EXPECT_EQ(scheduler.next(5.9), ProbeKind::kSmall);  // sized due at 6 (1 + 5)
  EXPECT_EQ(scheduler.next(5.9), ProbeKind::kNone);
  EXPECT_EQ(scheduler.next(6.0), ProbeKind::kSized);
  EXPECT_EQ(scheduler.next(6.0), ProbeKind::kNone);
}

TEST(ProbeScheduler, NoBurstAfterAPause) {
  ProbeScheduler scheduler;
  scheduler.next(0.0);
  scheduler.next(0.0);
  EXPECT_EQ(scheduler.next(30.0), ProbeKind::kSmall);
  EXPECT_EQ(scheduler.next(30.0), ProbeKind::kSized);
  EXPECT_EQ(scheduler.next(30.0), ProbeKind::kNone);
  EXPECT_EQ(scheduler.next(30.5), ProbeKind::kNone);
}

TEST(ProbeScheduler, SizedProbeTakesAboutFiveMillisecondsOfTransfer) {
  ProbeScheduler scheduler;
  EXPECT_EQ(scheduler.sizedProbeBytes(std::nullopt), 4096u);
  EXPECT_EQ(scheduler.sizedProbeBytes(2.0), 4096u);     // 1.25 kB would drown in jitter
  EXPECT_EQ(scheduler.sizedProbeBytes(40.0), 25000u);   // 5 ms at 40 Mbit/s
  EXPECT_EQ(scheduler.sizedProbeBytes(300.0), 65536u);  // capped
}

TEST(ProbeScheduler, CostsAFewKilobytesPerSecond) {
  ProbeScheduler scheduler;
  EXPECT_EQ(estimatedProbeWireBytes(32, 32), 32u + 32u + 250u + 104u);
  const double slow = scheduler.wireBytesPerSecond(2.0);
  const double fast = scheduler.wireBytesPerSecond(300.0);
  EXPECT_GT(slow, 1000.0);
  EXPECT_LT(slow, 2000.0);   // about 11 kbit/s: 0.6% of a 2 Mbit/s uplink
  EXPECT_LT(fast, 15000.0);  // about 0.1 Mbit/s on a 300 Mbit/s link
}

}  // namespace
}  // namespace edgeslam
