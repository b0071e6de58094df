#include "adapt/network_estimator.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

namespace edgeslam {
namespace {

TEST(NetworkTime, IsLatencyPlusTransferTime) {
  // 100 kB at 40 Mbit/s = 20 ms.
  EXPECT_DOUBLE_EQ(networkTimeMs(10.0, 40.0, 100e3), 30.0);
  EXPECT_DOUBLE_EQ(networkTimeMs(4.0, 200.0, 100e3), 8.0);
  EXPECT_TRUE(std::isinf(networkTimeMs(4.0, 0.0, 100e3)));
}

TEST(NetworkEstimator, NeedsLatencyBeforeBandwidth) {
  NetworkEstimator estimator;
  EXPECT_FALSE(estimator.latencyMs());
  EXPECT_FALSE(estimator.addBandwidthProbe(4096, 10.0));
  EXPECT_FALSE(estimator.networkTimeMs(1000));
  estimator.addLatencyProbe(10.0);
  EXPECT_FALSE(estimator.networkTimeMs(1000));
  // 10 kB in 12 ms with a 10 ms RTT: 10 kB per 2 ms = 40 Mbit/s.
  EXPECT_TRUE(estimator.addBandwidthProbe(10000, 12.0));
  EXPECT_NEAR(*estimator.bandwidthMbps(), 40.0, 1e-9);
  EXPECT_NEAR(*estimator.networkTimeMs(100e3), 30.0, 1e-9);
  // A probe no slower than the RTT moved its bytes faster than it can resolve: no sample while a
  // larger probe can follow; the largest counts at the resolution bound (10 kB in 0.05 ms =
  // 1600 Mbit/s), on the fast side of the median.
  EXPECT_FALSE(estimator.resolves(9.0));
  EXPECT_TRUE(estimator.resolves(12.0));
  EXPECT_FALSE(estimator.addBandwidthProbe(10000, 9.0, /*largest=*/false));
  EXPECT_NEAR(*estimator.bandwidthMbps(), 40.0, 1e-9);
  EXPECT_TRUE(estimator.addBandwidthProbe(10000, 9.0, /*largest=*/true));
  EXPECT_NEAR(*estimator.bandwidthMbps(), (40.0 + 1600.0) / 2, 1e-9);
  EXPECT_FALSE(estimator.addBandwidthProbe(0, 20.0));
  EXPECT_THROW(estimator.addLatencyProbe(-1.0), std::invalid_argument);
  EXPECT_THROW(estimator.addLatencyProbe(NAN), std::invalid_argument);
}

TEST(NetworkEstimator, OneOutlierDoesNotMoveTheEstimate) {
  NetworkEstimator estimator(5);
  for (double rtt : {20.0, 21.0, 19.0, 20.5}) estimator.addLatencyProbe(rtt);
  estimator.addLatencyProbe(480.0);  // a retransmission timeout
  EXPECT_NEAR(*estimator.latencyMs(), 20.5, 1e-9);
  for (double ms : {40.0, 41.0, 39.0, 40.0}) estimator.addBandwidthProbe(50000, ms);
  const double before = *estimator.bandwidthMbps();
  estimator.addBandwidthProbe(50000, 900.0);
  EXPECT_NEAR(*estimator.bandwidthMbps(), before, 0.05 * before);
}

TEST(NetworkEstimator, ProbesTooFastToResolveKeepAFastLinkFast) {
  // Loopback to a busy edge (KITTI 03, monocular, the edge mapping the first keyframes): most
  // 4 KiB probes come back within the 1 ms RTT, some wait ~5 ms for the edge's CPU. Counting only
  // the delayed ones made B 6.6 Mbit/s, N 70 ms and Table I's last row for the whole run.
  NetworkEstimator estimator(5);
  for (int i = 0; i < 5; ++i) estimator.addLatencyProbe(1.0);
  for (double ms : {6.0, 0.98, 5.5, 1.0, 0.99}) EXPECT_TRUE(estimator.addBandwidthProbe(4096, ms));
  EXPECT_GT(*estimator.bandwidthMbps(), 500.0);
  EXPECT_LT(*estimator.networkTimeMs(60e3), 2.0);
}

TEST(NetworkEstimator, FollowsALastingChange) {
  NetworkEstimator estimator(5);
  for (int i = 0; i < 5; ++i) estimator.addLatencyProbe(5.0);
  for (int i = 0; i < 3; ++i) estimator.addLatencyProbe(60.0);
  EXPECT_DOUBLE_EQ(*estimator.latencyMs(), 60.0);
}

}  // namespace
}  // namespace edgeslam
