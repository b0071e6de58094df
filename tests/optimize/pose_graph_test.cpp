#include "optimize/pose_graph.h"

#include <gtest/gtest.h>

#include <random>

#include "geometry/so3.h"
#include "synthetic_scene.h"

namespace edgeslam {
namespace {

Eigen::Vector3d cameraCentre(const Sim3d& S_cw) {
  return S_cw.inverse().translation();
}

// Keyframes on a circle of radius 5 m, each camera looking along the tangent.
std::vector<Sim3d> circleTruth(int count) {
  std::vector<Sim3d> truth;
  for (int k = 0; k < count; ++k) {
    const double a = 2.0 * M_PI * k / count;
    const Eigen::Quaterniond R_wc(Eigen::AngleAxisd(-a, Eigen::Vector3d::UnitY()));
    const SE3d T_wc(R_wc, Eigen::Vector3d(5.0 * std::cos(a), 0.0, 5.0 * std::sin(a)));
    truth.emplace_back(T_wc.inverse());
  }
  return truth;
}

Sim3d relative(const Sim3d& S_iw, const Sim3d& S_jw) {
  return S_jw * S_iw.inverse();
}

// Odometry edges between consecutive keyframes measured with a systematic error (what visual
// odometry accumulates), the vertices chained from them, and one loop edge measured exactly.
PoseGraph driftedLoop(const std::vector<Sim3d>& truth, double scale_drift, bool exact_odometry) {
  const Sim3d step_error(1.0 + scale_drift,
                         Eigen::Quaterniond(so3Exp(Eigen::Vector3d(0.0, 0.004, 0.002))),
                         Eigen::Vector3d(0.01, -0.005, 0.0));
  PoseGraph graph;
  graph.vertices.push_back({0, truth[0], true});
  for (std::size_t k = 1; k < truth.size(); ++k) {
    const Sim3d drifted_step = step_error * relative(truth[k - 1], truth[k]);
    const Sim3d S_kw = drifted_step * graph.vertices.back().S_cw;
    graph.vertices.push_back({k, S_kw, false});
    graph.edges.push_back(
        {k - 1, k, exact_odometry ? relative(truth[k - 1], truth[k]) : drifted_step});
  }
  const std::size_t last = truth.size() - 1;
  graph.edges.push_back({last, 0, relative(truth[last], truth[0])});
  return graph;
}

double meanCentreError(const std::vector<Sim3d>& estimate, const std::vector<Sim3d>& truth) {
  double sum = 0.0;
  for (std::size_t k = 0; k < truth.size(); ++k) {
    sum += (cameraCentre(estimate[k]) - cameraCentre(truth[k])).norm();
  }
  return sum / static_cast<double>(truth.size());
}

std::vector<Sim3d> vertexPoses(const PoseGraph& graph) {
  std::vector<Sim3d> poses;
  for (const PoseGraphVertex& v : graph.vertices) poses.push_back(v.S_cw);
  return poses;
}

TEST(PoseGraph, ConsistentConstraintsRecoverTheTruth) {
  const std::vector<Sim3d> truth = circleTruth(40);
  const PoseGraph graph = driftedLoop(truth, 0.01, /*exact_odometry=*/true);
  const double before = meanCentreError(vertexPoses(graph), truth);
  const PoseGraphResult result = optimizePoseGraph(graph);
  const double after = meanCentreError(result.S_cw, truth);
  std::printf("consistent loop: mean centre error %.3f m -> %.2e m\n", before, after);
  EXPECT_GT(before, 0.5);
  EXPECT_LT(after, 1e-5);
  for (std::size_t k = 0; k < truth.size(); ++k) EXPECT_NEAR(result.S_cw[k].scale(), 1.0, 1e-6);
  EXPECT_LT(result.final_cost, 1e-10);
}

TEST(PoseGraph, LoopEdgeCorrectsAccumulatedSim3Drift) {
  const std::vector<Sim3d> truth = circleTruth(40);
  const PoseGraph graph = driftedLoop(truth, 0.01, /*exact_odometry=*/false);
  const double before = meanCentreError(vertexPoses(graph), truth);
  const PoseGraphResult result = optimizePoseGraph(graph);
  const double after = meanCentreError(result.S_cw, truth);
  std::printf("drifted Sim3 loop: mean centre error %.3f m -> %.3f m, cost %.3g -> %.3g\n", before,
              after, result.initial_cost, result.final_cost);
  EXPECT_LT(after, 0.2 * before);
  EXPECT_LT(result.final_cost, 0.01 * result.initial_cost);
  // The last keyframe closes onto the first.
  EXPECT_LT((cameraCentre(result.S_cw.back()) - cameraCentre(truth.back())).norm(), 0.1 * before);
  EXPECT_EQ((result.S_cw[0].matrix() - truth[0].matrix()).norm(), 0.0);  // fixed vertex
}

TEST(PoseGraph, FixedScaleKeepsRigidPoses) {
  const std::vector<Sim3d> truth = circleTruth(30);
  const PoseGraph graph = driftedLoop(truth, 0.0, /*exact_odometry=*/false);
  const double before = meanCentreError(vertexPoses(graph), truth);
  PoseGraphOptions options;
  options.fix_scale = true;
  const PoseGraphResult result = optimizePoseGraph(graph, options);
  const double after = meanCentreError(result.S_cw, truth);
  std::printf("drifted SE3 loop: mean centre error %.3f m -> %.3f m\n", before, after);
  EXPECT_LT(after, 0.2 * before);
  for (const Sim3d& s : result.S_cw) EXPECT_DOUBLE_EQ(s.scale(), 1.0);
}

TEST(PoseGraph, CancelledBeforeStartReturnsTheInput) {
  const std::vector<Sim3d> truth = circleTruth(10);
  const PoseGraph graph = driftedLoop(truth, 0.01, false);
  std::atomic<bool> cancel{true};
  PoseGraphOptions options;
  options.cancel = &cancel;
  const PoseGraphResult result = optimizePoseGraph(graph, options);
  EXPECT_TRUE(result.cancelled);
  for (std::size_t k = 0; k < truth.size(); ++k) {
    EXPECT_LT((result.S_cw[k].matrix() - graph.vertices[k].S_cw.matrix()).norm(), 1e-12);
  }
}

TEST(PoseGraph, RejectsBadEdges) {
  PoseGraph graph = driftedLoop(circleTruth(5), 0.0, true);
  graph.edges[1].j = 17;
  EXPECT_THROW(optimizePoseGraph(graph), std::invalid_argument);
  graph = driftedLoop(circleTruth(5), 0.0, true);
  graph.edges[0].j = graph.edges[0].i;
  EXPECT_THROW(optimizePoseGraph(graph), std::invalid_argument);
  graph = driftedLoop(circleTruth(5), 0.0, true);
  graph.edges[2].information(0, 0) = -1.0;
  EXPECT_THROW(optimizePoseGraph(graph), std::invalid_argument);
}

}  // namespace
}  // namespace edgeslam
