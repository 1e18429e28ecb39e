#include "plslam/inertial/imu_residual.h"

#include <stdexcept>

#include <Eigen/Cholesky>

#include "plslam/core/imu.h"
#include "plslam/inertial/imu_pose_manifold.h"

namespace plslam::inertial {

Eigen::Vector3d world_gravity() { return Eigen::Vector3d(0.0, 0.0, -kGravity); }

ImuCost::ImuCost(const Preintegration& preintegration) : preintegration_(preintegration) {
  // Factored as S K K' S, S the standard deviations and K K' the correlation's Cholesky, so that
  // L = K^-1 S^-1 (L' L = covariance^-1) needs no inverse, and so that definiteness is judged free
  // of units: a covariance of rank < 9 (no noise; or a single step, whose velocity and position
  // errors come from the same noise) leaves a pivot at rounding level, whatever its sign.
  const Matrix9d& covariance = preintegration.covariance();
  const Vector9d sigma = covariance.diagonal().cwiseSqrt();
  if (!(sigma.minCoeff() > 0.0)) {
    throw std::invalid_argument("IMU residual: the preintegrated covariance has a zero variance");
  }
  const Vector9d inv_sigma = sigma.cwiseInverse();
  const Eigen::LLT<Matrix9d> llt(inv_sigma.asDiagonal() * covariance * inv_sigma.asDiagonal());
  if (llt.info() != Eigen::Success || !(llt.matrixLLT().diagonal().minCoeff() > 1e-6)) {
    throw std::invalid_argument(
        "IMU residual: the preintegrated covariance is not positive definite");
  }
  sqrt_info_ = llt.matrixL().solve(Matrix9d(inv_sigma.asDiagonal()));
}

bool ImuCost::Evaluate(double const* const* params, double* residuals, double** jacobians) const {
  const geometry::SE3 Ti = imu_pose_from_params(params[0]);
  const Eigen::Map<const Eigen::Vector3d> vi(params[1]);
  const ImuBias b = ImuBias::from_vector(params[2]);
  const geometry::SE3 Tj = imu_pose_from_params(params[3]);
  const Eigen::Map<const Eigen::Vector3d> vj(params[4]);

  const Preintegration& pre = preintegration_;
  const double dt = pre.dt();
  const Eigen::Matrix3d dR = pre.corrected_delta_R(b);
  const Eigen::Vector3d dv = pre.corrected_delta_v(b);
  const Eigen::Vector3d dp = pre.corrected_delta_p(b);

  const Eigen::Matrix3d& Ri = Ti.rotation();
  const Eigen::Matrix3d& Rj = Tj.rotation();
  const Eigen::Matrix3d Rit = Ri.transpose();
  const Eigen::Vector3d g = world_gravity();
  const Eigen::Vector3d v_rel = Rit * (vj - vi - g * dt);
  const Eigen::Vector3d p_rel =
      Rit * (Tj.translation() - Ti.translation() - vi * dt - 0.5 * dt * dt * g);
  const Eigen::Matrix3d E = dR.transpose() * Rit * Rj;
  const Eigen::Vector3d r_R = geometry::so3_log(E);
  Vector9d r;
  r << r_R, v_rel - dv, p_rel - dp;
  Eigen::Map<Vector9d> out(residuals);
  out = sqrt_info_ * r;
  if (!jacobians) return true;

  // Pose tangents are [dp; dphi] (imu_pose_manifold.h); J_r(x)^-1 = J_l(-x)^-1.
  const Eigen::Matrix3d Jr_inv = geometry::so3_left_jacobian_inverse(-r_R);
  using Jacobian97 = Eigen::Matrix<double, 9, 7, Eigen::RowMajor>;
  using Jacobian93 = Eigen::Matrix<double, 9, 3, Eigen::RowMajor>;
  if (jacobians[0]) {
    Eigen::Matrix<double, 9, 6> D = Eigen::Matrix<double, 9, 6>::Zero();
    D.block<3, 3>(6, 0) = -Eigen::Matrix3d::Identity();
    D.block<3, 3>(0, 3) = -Jr_inv * Rj.transpose() * Ri;
    D.block<3, 3>(3, 3) = geometry::hat(v_rel);
    D.block<3, 3>(6, 3) = geometry::hat(p_rel);
    Eigen::Map<Jacobian97> J(jacobians[0]);
    J.leftCols<6>() = sqrt_info_ * D;
    J.col(6).setZero();
  }
  if (jacobians[1]) {
    Eigen::Matrix<double, 9, 3> D;
    D << Eigen::Matrix3d::Zero(), -Rit, -dt * Rit;
    Eigen::Map<Jacobian93> J(jacobians[1]);
    J = sqrt_info_ * D;
  }
  if (jacobians[2]) {
    // With phi_b = dR_dbg (bg - bg_lin): Exp(phi_b + dR_dbg e) ~= Exp(phi_b) Exp(J_r(phi_b) dR_dbg
    // e), which Log(E) sees through E' (Exp(a) E = E Exp(E' a)).
    const Eigen::Matrix3d dR_dbg = pre.dR_dbg();
    const Eigen::Vector3d phi_b = dR_dbg * (b.gyro - pre.linearisation_bias().gyro);
    Eigen::Matrix<double, 9, 6> D = -pre.bias_jacobian();
    D.block<3, 3>(0, 0) = -Jr_inv * E.transpose() * geometry::so3_left_jacobian(-phi_b) * dR_dbg;
    Eigen::Map<Eigen::Matrix<double, 9, 6, Eigen::RowMajor>> J(jacobians[2]);
    J = sqrt_info_ * D;
  }
  if (jacobians[3]) {
    Eigen::Matrix<double, 9, 6> D = Eigen::Matrix<double, 9, 6>::Zero();
    D.block<3, 3>(0, 3) = Jr_inv;
    D.block<3, 3>(6, 0) = Rit * Rj;
    Eigen::Map<Jacobian97> J(jacobians[3]);
    J.leftCols<6>() = sqrt_info_ * D;
    J.col(6).setZero();
  }
  if (jacobians[4]) {
    Eigen::Matrix<double, 9, 3> D;
    D << Eigen::Matrix3d::Zero(), Rit, Eigen::Matrix3d::Zero();
    Eigen::Map<Jacobian93> J(jacobians[4]);
    J = sqrt_info_ * D;
  }
  return true;
}

}  // namespace plslam::inertial
