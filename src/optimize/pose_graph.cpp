#include "optimize/pose_graph.h"

#include <ceres/autodiff_cost_function.h>
#include <ceres/manifold.h>
#include <ceres/problem.h>
#include <ceres/solver.h>

#include <Eigen/Cholesky>
#include <stdexcept>
#include <string>

#include "optimize/sim3_parameters.h"

namespace edgeslam {
namespace {

bool finite(const Sim3d& s) {
  return std::isfinite(s.scale()) && s.rotation().coeffs().allFinite() &&
         s.translation().allFinite();
}

// sqrt_information * error(S_ji_measured^-1 * S_jw * S_iw^-1).
class RelativeSim3Cost {
 public:
  RelativeSim3Cost(const Sim3d& S_ji, const Eigen::Matrix<double, 7, 7>& sqrt_information)
      : S_ij_measured_(S_ji.inverse()), sqrt_information_(sqrt_information) {}

  template <typename T>
  bool operator()(const T* q_i, const T* t_i, const T* s_i, const T* q_j, const T* t_j,
                  const T* s_j, T* residual) const {
    const Sim3T<T> S_iw = Sim3T<T>::fromBlocks(q_i, t_i, s_i);
    const Sim3T<T> S_jw = Sim3T<T>::fromBlocks(q_j, t_j, s_j);
    const Sim3T<T> error = Sim3T<T>::fromSim3(S_ij_measured_) * S_jw * S_iw.inverse();
    Eigen::Map<Eigen::Matrix<T, 7, 1>> r(residual);
    r = sqrt_information_.cast<T>() * error.errorVector();
    return true;
  }

 private:
  Sim3d S_ij_measured_;
  Eigen::Matrix<double, 7, 7> sqrt_information_;
};

// Upper factor U with U^T U = information, so that |U r|^2 = r^T information r.
Eigen::Matrix<double, 7, 7> sqrtInformation(const Eigen::Matrix<double, 7, 7>& information,
                                            std::size_t edge) {
  const auto fail = [edge](const std::string& what) {
    throw std::invalid_argument("optimizePoseGraph: edge " + std::to_string(edge) + ": " + what);
  };
  if (!information.allFinite() || !information.isApprox(information.transpose(), 1e-9)) {
    fail("information matrix must be finite and symmetric");
  }
  const Eigen::LLT<Eigen::Matrix<double, 7, 7>> llt(information);
  if (llt.info() != Eigen::Success) fail("information matrix is not positive definite");
  return llt.matrixU();
}

void validate(const PoseGraph& graph) {
  for (std::size_t v = 0; v < graph.vertices.size(); ++v) {
    if (!finite(graph.vertices[v].S_cw)) {
      throw std::invalid_argument("optimizePoseGraph: vertex " + std::to_string(v) + " (id " +
                                  std::to_string(graph.vertices[v].id) + ") is not finite");
    }
  }
  for (std::size_t e = 0; e < graph.edges.size(); ++e) {
    const PoseGraphEdge& edge = graph.edges[e];
    const std::string name = "optimizePoseGraph: edge " + std::to_string(e) + ": ";
    if (edge.i >= graph.vertices.size() || edge.j >= graph.vertices.size()) {
      throw std::invalid_argument(name + "vertex index out of range (" + std::to_string(edge.i) +
                                  ", " + std::to_string(edge.j) + ")");
    }
    if (edge.i == edge.j) throw std::invalid_argument(name + "connects a vertex to itself");
    if (!finite(edge.S_ji)) throw std::invalid_argument(name + "measurement is not finite");
  }
}

}  // namespace

PoseGraphResult optimizePoseGraph(const PoseGraph& graph, const PoseGraphOptions& options) {
  validate(graph);
  PoseGraphResult result;
  std::vector<Sim3Blocks> blocks;
  blocks.reserve(graph.vertices.size());
  for (const PoseGraphVertex& v : graph.vertices) blocks.push_back(Sim3Blocks::from(v.S_cw));

  const auto finish = [&]() {
    result.S_cw.clear();
    for (const Sim3Blocks& b : blocks) result.S_cw.push_back(b.toSim3());
    return result;
  };
  if (options.cancel != nullptr && options.cancel->load()) {
    result.cancelled = true;
    return finish();
  }

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  ceres::EigenQuaternionManifold quaternion_manifold;
  for (std::size_t e = 0; e < graph.edges.size(); ++e) {
    const PoseGraphEdge& edge = graph.edges[e];
    auto* cost = new ceres::AutoDiffCostFunction<RelativeSim3Cost, 7, 4, 3, 1, 4, 3, 1>(
        new RelativeSim3Cost(edge.S_ji, sqrtInformation(edge.information, e)));
    Sim3Blocks& a = blocks[edge.i];
    Sim3Blocks& b = blocks[edge.j];
    problem.AddResidualBlock(cost, nullptr, a.rotation.data(), a.translation.data(), &a.log_scale,
                             b.rotation.data(), b.translation.data(), &b.log_scale);
  }
  if (problem.NumResidualBlocks() == 0) return finish();

  for (std::size_t v = 0; v < blocks.size(); ++v) {
    Sim3Blocks& b = blocks[v];
    if (!problem.HasParameterBlock(b.rotation.data())) continue;  // isolated vertex
    problem.SetManifold(b.rotation.data(), &quaternion_manifold);
    if (graph.vertices[v].fixed) {
      problem.SetParameterBlockConstant(b.rotation.data());
      problem.SetParameterBlockConstant(b.translation.data());
    }
    if (graph.vertices[v].fixed || options.fix_scale) {
      problem.SetParameterBlockConstant(&b.log_scale);
    }
  }

  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver_options.max_num_iterations = options.max_iterations;
  solver_options.num_threads = options.num_threads;
  solver_options.logging_type = ceres::SILENT;
  SolverControlCallback control(options.cancel, options.on_iteration, 0);
  solver_options.callbacks.push_back(&control);
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);

  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.iterations = control.iterations();
  result.cancelled = control.cancelledDuringSolve();
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  if (!summary.IsSolutionUsable()) {
    for (std::size_t v = 0; v < blocks.size(); ++v)
      blocks[v] = Sim3Blocks::from(graph.vertices[v].S_cw);
  }
  return finish();
}

}  // namespace edgeslam
