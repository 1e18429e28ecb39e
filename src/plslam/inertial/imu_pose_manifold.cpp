#include "plslam/inertial/imu_pose_manifold.h"

#include <algorithm>

namespace plslam::inertial {

bool ImuPoseManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const geometry::SE3 T = imu_pose_from_params(x);
  const Eigen::Map<const Eigen::Vector3d> dp(delta);
  const Eigen::Map<const Eigen::Vector3d> dphi(delta + 3);
  const ImuPoseParams out = imu_pose_params(
      geometry::SE3(T.rotation() * geometry::so3_exp(dphi), T.translation() + T.rotation() * dp));
  std::copy(out.begin(), out.end(), x_plus_delta);
  return true;
}

bool ImuPoseManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool ImuPoseManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const geometry::SE3 Ty = imu_pose_from_params(y);
  const geometry::SE3 Tx = imu_pose_from_params(x);
  const Eigen::Matrix3d Rxt = Tx.rotation().transpose();
  Eigen::Map<Eigen::Vector3d> dp(y_minus_x);
  Eigen::Map<Eigen::Vector3d> dphi(y_minus_x + 3);
  dp = Rxt * (Ty.translation() - Tx.translation());
  dphi = geometry::so3_log(Rxt * Ty.rotation());
  return true;
}

bool ImuPoseManifold::MinusJacobian(const double*, double* jacobian) const {
  // Consistent with PlusJacobian: Minus o Plus is the identity on delta to first order.
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

}  // namespace plslam::inertial
