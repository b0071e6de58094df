#pragma once
// Every observation of a pose-only problem in one Ceres residual block of seven rows: the
// normal equations, compressed. With one block of 2-3 residuals per observation (the textbook
// formulation), Ceres' per-block bookkeeping and its passes over the tall Jacobian cost more than
// the reprojections themselves, and a tracking frame has hundreds of observations.
//
// Evaluate accumulates, over the observations, the Gauss-Newton Hessian H = sum w J^T J, the
// gradient g = sum w J^T r and the cost sum rho(s), exactly as Ceres forms them for one block per
// observation under a HuberLoss (its corrector scales a Huber block's residual and Jacobian by
// sqrt(rho'(s)), w = rho'(s)). It then hands Ceres a 7 x 7 block with rows [L^T 0] and [0 0]
// (H = L L^T) and residuals [L^-1 g; c], c chosen so that the squared norm is sum rho(s). Ceres
// sees the same cost, gradient and Hessian as with the textbook formulation, so it takes the
// same trust-region steps; it just works on 7 rows instead of ~1500.
#include <ceres/cost_function.h>

#include <Eigen/Core>
#include <vector>

#include "optimize/camera_projection.h"
#include "optimize/reprojection_error.h"

namespace edgeslam {

struct PoseBatchTerm {
  Eigen::Vector3d point_world = Eigen::Vector3d::Zero();
  PixelMeasurement measurement;
  bool stereo = false;       // 3 residuals (u, v, u_right) instead of 2
  double huber_delta = 0.0;  // Huber threshold on the whitened error norm; 0: plain least squares
};

class PoseBatchReprojectionCost final : public ceres::CostFunction {
 public:
  static constexpr int kRows = 7;

  PoseBatchReprojectionCost(const CameraProjection& camera, std::vector<PoseBatchTerm> terms);

  // Fails (Ceres then rejects the step) when a point falls behind the camera.
  bool Evaluate(double const* const* parameters, double* residuals,
                double** jacobians) const override;

 private:
  CameraProjection camera_;
  std::vector<PoseBatchTerm> terms_;
};

}  // namespace edgeslam
