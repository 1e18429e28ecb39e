#pragma once
// The pose block of the inertial costs: the body (IMU) pose in the world, T_wb, as 7 doubles
// [p_x p_y p_z q_x q_y q_z q_w] (the layout of optim/'s pose blocks, but of T_wb, not T_cw), and
// its manifold. The tangent is delta = [dp; dphi] (translation first, as geometry/'s SE(3)
// tangents), both in the body frame:
//   R <- R Exp(dphi),   p <- p + R dp,
// Forster's retraction, under which the IMU residuals' Jacobians are simplest. As in optim/, the
// PlusJacobian is [I_6; 0] and every cost writes its Jacobian w.r.t. delta into the first 6 of the
// 7 ambient columns (zero in the last), so that Ceres' J_ambient * PlusJacobian is the Jacobian
// w.r.t. delta.
#include <array>

#include <ceres/manifold.h>

#include "plslam/geometry/se3.h"

namespace plslam::inertial {

using ImuPoseParams = geometry::PoseParams;
inline ImuPoseParams imu_pose_params(const geometry::SE3& T_wb) { return geometry::to_pose_params(T_wb); }
inline geometry::SE3 imu_pose_from_params(const double* x) { return geometry::from_pose_params(x); }

class ImuPoseManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // y - x = [R_x' (p_y - p_x); Log(R_x' R_y)], the inverse of Plus.
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

}  // namespace plslam::inertial
