#include "plslam/inertial/midpoint_step.h"

#include "plslam/geometry/se3.h"

namespace plslam::inertial {

PreintegratedDeltas midpoint_step(const PreintegratedDeltas& d, const Eigen::Vector3d& gyro,
                                  const Eigen::Vector3d& acc, double dt,
                                  StepTransition* transition) {
  const Eigen::Vector3d theta = gyro * dt;
  const Eigen::Matrix3d E = geometry::so3_exp(theta);
  const Eigen::Matrix3d H = geometry::so3_exp(0.5 * theta);
  const Eigen::Matrix3d M = d.R * H;
  const Eigen::Vector3d dv = M * acc * dt;
  PreintegratedDeltas out;
  out.R = d.R * E;
  out.v = d.v + dv;
  out.p = d.p + d.v * dt + 0.5 * dt * dv;
  if (!transition) return out;

  // M Exp(e_M) a ~= M a - M [a]x e_M, where e_M = H' dphi + J_r(theta / 2) (dt / 2) n_g is the
  // mid-step rotation's error; J_r(x) = J_l(-x).
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Ma = M * geometry::hat(acc);
  const Eigen::Matrix3d mid_from_phi = Ma * H.transpose();
  const Eigen::Matrix3d mid_from_gyro = Ma * geometry::so3_left_jacobian(-0.5 * theta) * (0.5 * dt);
  Matrix9d& A = transition->A;
  A.setIdentity();
  A.block<3, 3>(0, 0) = E.transpose();
  A.block<3, 3>(3, 0) = -dt * mid_from_phi;
  A.block<3, 3>(6, 0) = -0.5 * dt * dt * mid_from_phi;
  A.block<3, 3>(6, 3) = dt * I;
  Matrix96d& B = transition->B;
  B.setZero();
  B.block<3, 3>(0, 0) = geometry::so3_left_jacobian(-theta) * dt;
  B.block<3, 3>(3, 0) = -dt * mid_from_gyro;
  B.block<3, 3>(6, 0) = -0.5 * dt * dt * mid_from_gyro;
  B.block<3, 3>(3, 3) = dt * M;
  B.block<3, 3>(6, 3) = 0.5 * dt * dt * M;
  return out;
}

}  // namespace plslam::inertial
