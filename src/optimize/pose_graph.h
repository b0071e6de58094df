#pragma once
// Pose-graph optimisation for loop closing: keyframe poses S_cw (Sim3, or SE3 with the scale held
// at its initial value for stereo / RGB-D) tied by relative constraints from the spanning tree,
// covisibility and loop edges; some vertices fixed (the loop keyframe, the origin).
#include <Eigen/Core>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "geometry/sim3.h"
#include "optimize/solver_control.h"

namespace edgeslam {

struct PoseGraphVertex {
  std::uint64_t id = 0;
  Sim3d S_cw;  // camera-from-world, scale 1 for a rigid pose
  bool fixed = false;
};

struct PoseGraphEdge {
  std::size_t i = 0;  // vertex indices
  std::size_t j = 0;
  // Measured transform from camera i to camera j, i.e. S_jw * S_iw^-1 when it was observed.
  Sim3d S_ji;
  // Over the residual [translation; rotation vector; log scale] of S_ji^-1 * S_jw * S_iw^-1.
  Eigen::Matrix<double, 7, 7> information = Eigen::Matrix<double, 7, 7>::Identity();
};

struct PoseGraph {
  std::vector<PoseGraphVertex> vertices;
  std::vector<PoseGraphEdge> edges;
};

struct PoseGraphOptions {
  int max_iterations = 20;
  bool fix_scale = false;  // SE3 graph: every vertex keeps its scale
  const std::atomic<bool>* cancel = nullptr;
  IterationHook on_iteration;
  int num_threads = 1;
};

struct PoseGraphResult {
  std::vector<Sim3d> S_cw;  // one per vertex
  double initial_cost = 0.0;
  double final_cost = 0.0;
  int iterations = 0;
  bool cancelled = false;
  bool converged = false;
};

// Throws std::invalid_argument for out-of-range vertex indices, self edges, non-finite values or an
// information matrix that is not symmetric positive definite.
PoseGraphResult optimizePoseGraph(const PoseGraph& graph, const PoseGraphOptions& options = {});

}  // namespace edgeslam
