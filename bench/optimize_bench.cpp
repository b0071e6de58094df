// Pose-only optimisation as tracking runs it (RGB-D: 600 observations, two thirds with a right
// coordinate, 10 % outliers), with all observations in one residual block against the reference
// formulation of one Ceres block per observation, in the same run.
#include <benchmark/benchmark.h>

#include <cmath>
#include <random>
#include <vector>

#include "optimize/pose_optimizer.h"

namespace edgeslam {
namespace {

struct PoseScene {
  SE3d T_cw;
  SE3d start;
  CameraProjection camera;
  std::vector<PoseObservation> observations;
};

PoseScene makeRgbdScene(int count) {
  PoseScene scene;
  scene.camera.fx = scene.camera.fy = 585.0;
  scene.camera.cx = 320.0;
  scene.camera.cy = 240.0;
  scene.camera.bf = 40.0;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 640.0), v(0.0, 480.0), depth(0.8, 4.0);
  std::normal_distribution<double> noise(0.0, 1.0);
  scene.T_cw =
      SE3d::exp((Eigen::Matrix<double, 6, 1>() << 0.3, -0.1, 0.2, 0.05, 0.1, -0.02).finished());
  const SE3d T_wc = scene.T_cw.inverse();
  for (int i = 0; i < count; ++i) {
    const double z = depth(rng), px = u(rng), py = v(rng);
    const Eigen::Vector3d pc((px - scene.camera.cx) * z / scene.camera.fx,
                             (py - scene.camera.cy) * z / scene.camera.fy, z);
    PoseObservation o;
    o.point_world = T_wc * pc;
    o.pixel = Eigen::Vector2d(px + noise(rng), py + noise(rng));
    if (i % 10 == 0) o.pixel += Eigen::Vector2d(30.0, -20.0);
    if (i % 3 != 0) o.right_u = px - scene.camera.bf / z + noise(rng);
    o.inv_sigma2 = 1.0 / std::pow(1.2, 2 * (i % 4));
    scene.observations.push_back(o);
  }
  scene.start =
      SE3d::exp((Eigen::Matrix<double, 6, 1>() << 0.01, 0.0, -0.01, 0.005, 0.0, 0.004).finished()) *
      scene.T_cw;
  return scene;
}

void solve(benchmark::State& state, bool single_block) {
  const PoseScene scene = makeRgbdScene(static_cast<int>(state.range(0)));
  PoseOptimizerOptions options;
  options.single_residual_block = single_block;
  PoseOptimizerResult result;
  for (auto _ : state) {
    result = optimizePose(scene.start, scene.observations, scene.camera, options);
    benchmark::DoNotOptimize(result.T_cw);
  }
  state.counters["inliers"] = result.inliers;
  state.counters["iterations"] = result.iterations;
}

void BM_PoseOnly_SingleBlock(benchmark::State& state) {
  solve(state, true);
}
void BM_PoseOnly_BlockPerObservation(benchmark::State& state) {
  solve(state, false);
}

BENCHMARK(BM_PoseOnly_SingleBlock)->Arg(600)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_PoseOnly_BlockPerObservation)->Arg(600)->Unit(benchmark::kMicrosecond);

}  // namespace
}  // namespace edgeslam

BENCHMARK_MAIN();
