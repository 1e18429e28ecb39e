#pragma once
// The preintegrated IMU residual between body states i and j (Forster et al., TRO 2017, eq. 45),
// with the deltas corrected to first order for state i's bias:
//   r_R = Log(delta_R(b_i)' R_i' R_j)
//   r_v = R_i' (v_j - v_i - g dt) - delta_v(b_i)
//   r_p = R_i' (p_j - p_i - v_i dt - g dt^2 / 2) - delta_p(b_i)
// whitened by L with L' L = covariance^-1 of the preintegration. The world's z axis points up,
// g = (0, 0, -kGravity).
//
// Blocks: pose_i (7, T_wb, ImuPoseManifold), v_i (3, world), bias_i (6, [bg; ba]),
// pose_j (7), v_j (3). Residual rows: [r_R; r_v; r_p].
#include <ceres/sized_cost_function.h>

#include "plslam/inertial/midpoint_step.h"
#include "plslam/inertial/preintegration.h"

namespace plslam::inertial {

// (0, 0, -kGravity): the world's gravity.
Eigen::Vector3d world_gravity();

class ImuCost final : public ceres::SizedCostFunction<9, 7, 3, 6, 7, 3> {
 public:
  // Keeps a copy of the preintegration. Throws std::invalid_argument when its covariance is not
  // positive definite (a noise density of zero, or an interval of a single step).
  explicit ImuCost(const Preintegration& preintegration);
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override;

  // L, lower triangular, L' L = covariance^-1.
  const Matrix9d& sqrt_information() const { return sqrt_info_; }

 private:
  Preintegration preintegration_;
  Matrix9d sqrt_info_;
};

}  // namespace plslam::inertial
