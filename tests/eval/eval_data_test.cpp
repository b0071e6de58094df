// Reference figures on the shared trajectories: the TUM benchmark's ATE on fr2/desk, and the
// KITTI metric on sequence 00 (cross-checked with an independent numpy implementation).
#include <gtest/gtest.h>

#include "eval/ate.h"
#include "eval/kitti_metric.h"
#include "eval/trajectory_input.h"
#include "support/shared_data.h"

namespace edgeslam {
namespace {

const std::string kEvo = "datasets/trajectories/evo/";

PosePairs loadPairs(const std::string& gt, const std::string& est) {
  return pairTrajectories(loadTrajectory(test::sharedPath(gt), TrajectoryFormat::kAuto),
                          loadTrajectory(test::sharedPath(est), TrajectoryFormat::kAuto), 0.02);
}

// TUM's evaluate_ate.py: 2223 pairs, RMSE 0.008144, mean 0.007514, median 0.007432,
// std 0.003140, min 0.000332, max 0.024329 (evo, with another association: RMSE 0.008119).
TEST(EvalReference, Fr2DeskAteMatchesTumBenchmarkScript) {
  EDGESLAM_REQUIRE_SHARED(kEvo + "fr2_desk_ORB.txt");
  const PosePairs pairs = loadPairs(kEvo + "fr2_desk_groundtruth.txt", kEvo + "fr2_desk_ORB.txt");
  EXPECT_EQ(pairs.size(), 2223U);
  const AteResult r = computeAte(pairs, AlignMode::kSe3);
  EXPECT_NEAR(r.translation.rmse, 0.008144, 5e-5);
  EXPECT_NEAR(r.translation.mean, 0.007514, 5e-5);
  EXPECT_NEAR(r.translation.median, 0.007432, 5e-5);
  EXPECT_NEAR(r.translation.std, 0.003140, 5e-5);
  EXPECT_NEAR(r.translation.min, 0.000332, 5e-5);
  EXPECT_NEAR(r.translation.max, 0.024329, 5e-5);
  // Tighter: the script's figures are rounded to 6 decimals.
  EXPECT_NEAR(r.translation.rmse, 0.008144, 5e-7);
  EXPECT_EQ(r.alignment.scale(), 1.0);
}

struct KittiReference {
  const char* estimate;
  double t_rel_percent;
  double r_rel_deg_per_100m;
  double ate_se3_m;
  double ate_sim3_m;
};

class KittiSequence00 : public ::testing::TestWithParam<KittiReference> {};

// Figures from an independent numpy implementation of the devkit convention.
TEST_P(KittiSequence00, MatchesIndependentImplementation) {
  const KittiReference& ref = GetParam();
  EDGESLAM_REQUIRE_SHARED(kEvo + ref.estimate);
  const PosePairs pairs = loadPairs(kEvo + "KITTI_00_gt.txt", kEvo + ref.estimate);
  ASSERT_EQ(pairs.size(), 4541U);
  const KittiResult r = computeKittiMetric(pairs);
  EXPECT_EQ(r.segments.size(), 3283U);
  EXPECT_NEAR(r.t_rel_percent, ref.t_rel_percent, 1e-4);
  EXPECT_NEAR(r.r_rel_deg_per_100m, ref.r_rel_deg_per_100m, 1e-4);
  ASSERT_EQ(r.per_length.size(), 8U);
  EXPECT_EQ(r.per_length.front().segments, 445U);
  EXPECT_EQ(r.per_length.back().segments, 375U);
  EXPECT_NEAR(computeAte(pairs, AlignMode::kSe3).translation.rmse, ref.ate_se3_m, 1e-4);
  EXPECT_NEAR(computeAte(pairs, AlignMode::kSim3).translation.rmse, ref.ate_sim3_m, 1e-4);
}

INSTANTIATE_TEST_SUITE_P(EvoEstimates, KittiSequence00,
                         ::testing::Values(KittiReference{"KITTI_00_ORB.txt", 0.699729, 0.253330,
                                                          1.303450, 0.937709},
                                           KittiReference{"KITTI_00_SPTAM.txt", 1.486961, 0.557706,
                                                          3.738488, 3.635294}));

TEST(EvalReference, KittiGroundTruthAgainstItselfIsZero) {
  EDGESLAM_REQUIRE_SHARED("datasets/trajectories/kitti-gt/07.txt");
  const std::string path = "datasets/trajectories/kitti-gt/07.txt";
  const KittiResult r = computeKittiMetric(loadPairs(path, path));
  EXPECT_GT(r.segments.size(), 0U);
  EXPECT_LT(r.t_rel_percent, 1e-9);
  EXPECT_LT(r.r_rel_deg_per_100m, 1e-4);  // acos near 1 resolves angles only to ~1e-8 rad
}

}  // namespace
}  // namespace edgeslam
