#include "optimize/pose_batch_cost.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "optimize/se3_manifold.h"

namespace edgeslam {
namespace {

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

struct NormalEquations {
  Matrix6d H = Matrix6d::Zero();
  Vector6d g = Vector6d::Zero();
  double cost2 = 0.0;  // sum of rho(s): twice the cost
};

// Adds one observation; false when its point is not in front of the camera.
template <int kResiduals>
bool accumulate(const CameraProjection& camera, const PoseBatchTerm& term,
                const Eigen::Quaterniond& q, const Eigen::Vector3d& t, bool want_jacobian,
                NormalEquations& sum) {
  const Eigen::Vector3d pc = q * term.point_world + t;
  Eigen::Matrix<double, kResiduals, 1> r;
  Eigen::Matrix<double, kResiduals, 3> d_r_d_pc;
  if (!whitenedReprojection<kResiduals>(camera, pc, term.measurement, r.data(),
                                        want_jacobian ? &d_r_d_pc : nullptr)) {
    return false;
  }
  const double s = r.squaredNorm();
  double weight = 1.0;  // rho'(s)
  if (term.huber_delta > 0.0 && s > term.huber_delta * term.huber_delta) {
    const double norm = std::sqrt(s);
    weight = term.huber_delta / norm;
    sum.cost2 += 2.0 * term.huber_delta * norm - term.huber_delta * term.huber_delta;
  } else {
    sum.cost2 += s;
  }
  if (want_jacobian) {
    const Eigen::Matrix<double, kResiduals, 6> J = d_r_d_pc * pointJacobianWrtLeftPose(pc);
    sum.H.noalias() += weight * (J.transpose() * J);
    sum.g.noalias() += weight * (J.transpose() * r);
  }
  return true;
}

// R (6 x 6) and rho with R^T R = H and R^T rho = g; rank-deficient directions get zero rows.
void compress(const NormalEquations& sum, Matrix6d& R, Vector6d& rho) {
  const Eigen::LLT<Matrix6d> llt(sum.H);
  if (llt.info() == Eigen::Success) {
    R = llt.matrixU();
    rho = llt.matrixL().solve(sum.g);
    return;
  }
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(sum.H);
  const double floor = 1e-12 * std::max(1.0, eigen.eigenvalues().cwiseAbs().maxCoeff());
  R.setZero();
  rho.setZero();
  for (int k = 0; k < 6; ++k) {
    const double lambda = eigen.eigenvalues()(k);
    if (!(lambda > floor)) continue;
    const Vector6d v = eigen.eigenvectors().col(k);
    R.row(k) = std::sqrt(lambda) * v.transpose();
    rho(k) = v.dot(sum.g) / std::sqrt(lambda);
  }
}

}  // namespace

PoseBatchReprojectionCost::PoseBatchReprojectionCost(const CameraProjection& camera,
                                                     std::vector<PoseBatchTerm> terms)
    : camera_(camera), terms_(std::move(terms)) {
  set_num_residuals(kRows);
  mutable_parameter_block_sizes()->push_back(kPoseBlockSize);
}

bool PoseBatchReprojectionCost::Evaluate(double const* const* parameters, double* residuals,
                                         double** jacobians) const {
  const double* x = parameters[0];
  const Eigen::Quaterniond q = Eigen::Map<const Eigen::Quaterniond>(x);
  const Eigen::Vector3d t(x[4], x[5], x[6]);
  const bool want_jacobian = jacobians != nullptr && jacobians[0] != nullptr;
  NormalEquations sum;
  for (const PoseBatchTerm& term : terms_) {
    const bool ok = term.stereo
                        ? accumulate<kStereoResiduals>(camera_, term, q, t, want_jacobian, sum)
                        : accumulate<kMonoResiduals>(camera_, term, q, t, want_jacobian, sum);
    if (!ok) return false;
  }
  Eigen::Map<Eigen::Matrix<double, kRows, 1>> out(residuals);
  if (!want_jacobian) {  // only the cost is read
    out.setZero();
    out(6) = std::sqrt(sum.cost2);
    return true;
  }
  Matrix6d R;
  Vector6d rho;
  compress(sum, R, rho);
  out.head<6>() = rho;
  // sum rho(s) >= g^T H^-1 g (a projection of the weighted residuals, and rho(s) >= rho'(s) s).
  out(6) = std::sqrt(std::max(0.0, sum.cost2 - rho.squaredNorm()));
  Eigen::Map<Eigen::Matrix<double, kRows, kPoseBlockSize, Eigen::RowMajor>> J(jacobians[0]);
  J.setZero();
  J.topLeftCorner<6, 6>() = R;
  return true;
}

}  // namespace edgeslam
