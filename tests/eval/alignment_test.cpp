#include "eval/alignment.h"

#include <gtest/gtest.h>

#include "eval/eval_error.h"
#include "synthetic_trajectories.h"

namespace edgeslam {
namespace {

const Sim3d kTrueAlignment(
    2.5, Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized())),
    Eigen::Vector3d(3.0, -1.0, 0.25));

std::vector<Eigen::Vector3d> groundTruthPoints() {
  std::vector<Eigen::Vector3d> points;
  for (const StampedPose& p : test::wavyTrajectory(200)) points.push_back(p.pose.translation());
  return points;
}

std::vector<Eigen::Vector3d> mapped(const Sim3d& s, const std::vector<Eigen::Vector3d>& points) {
  std::vector<Eigen::Vector3d> out;
  for (const auto& p : points) out.push_back(s * p);
  return out;
}

TEST(Alignment, Sim3RecoversScaleRotationAndTranslation) {
  const auto gt = groundTruthPoints();
  const auto est = mapped(kTrueAlignment.inverse(), gt);
  const Sim3d s = alignPositions(est, gt, AlignMode::kSim3);
  EXPECT_NEAR(s.scale(), 2.5, 1e-9);
  EXPECT_LT(s.rotation().angularDistance(kTrueAlignment.rotation()), 1e-9);
  EXPECT_LT((s.translation() - kTrueAlignment.translation()).norm(), 1e-8);
}

TEST(Alignment, Se3KeepsUnitScaleAndRecoversRigidMotion) {
  const Sim3d rigid(1.0, kTrueAlignment.rotation(), kTrueAlignment.translation());
  const auto gt = groundTruthPoints();
  const Sim3d s = alignPositions(mapped(rigid.inverse(), gt), gt, AlignMode::kSe3);
  EXPECT_NEAR(s.scale(), 1.0, 1e-12);
  EXPECT_LT(s.rotation().angularDistance(rigid.rotation()), 1e-9);
  EXPECT_LT((s.translation() - rigid.translation()).norm(), 1e-9);
}

TEST(Alignment, Se3DoesNotFitScale) {
  const auto gt = groundTruthPoints();
  const Sim3d s = alignPositions(mapped(kTrueAlignment.inverse(), gt), gt, AlignMode::kSe3);
  EXPECT_NEAR(s.scale(), 1.0, 1e-12);
}

TEST(Alignment, NoneIsIdentity) {
  const auto gt = groundTruthPoints();
  const Sim3d s = alignPositions(mapped(kTrueAlignment, gt), gt, AlignMode::kNone);
  EXPECT_EQ(s.scale(), 1.0);
  EXPECT_EQ(s.translation(), Eigen::Vector3d::Zero());
}

TEST(Alignment, RejectsTooFewOrDegeneratePoints) {
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_THROW(alignPositions(two, two, AlignMode::kSe3), EvalError);
  const std::vector<Eigen::Vector3d> same(5, Eigen::Vector3d(1, 2, 3));
  EXPECT_THROW(alignPositions(same, groundTruthPoints(), AlignMode::kSim3), EvalError);
  EXPECT_THROW(alignPositions(same, same, AlignMode::kSim3), EvalError);
  EXPECT_NO_THROW(alignPositions({{1, 2, 3}}, {{0, 0, 0}}, AlignMode::kNone));
}

TEST(Alignment, ParsesModeNames) {
  EXPECT_EQ(parseAlignMode("sim3"), AlignMode::kSim3);
  EXPECT_EQ(parseAlignMode("se3"), AlignMode::kSe3);
  EXPECT_EQ(parseAlignMode("none"), AlignMode::kNone);
  EXPECT_EQ(toString(AlignMode::kSim3), "sim3");
  EXPECT_THROW(parseAlignMode("affine"), EvalError);
}

}  // namespace
}  // namespace edgeslam
