#include "plslam/optim/ceres_costs.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

#include "plslam/optim/stereo_line_residual.h"
#include "plslam/optim/stereo_point_residual.h"

namespace plslam::optim {

using geometry::SE3;

bool SE3LeftManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const geometry::Vector6d d = Eigen::Map<const geometry::Vector6d>(delta);
  const PoseParams out = to_params(SE3::exp(d) * from_params(x));
  std::copy(out.begin(), out.end(), x_plus_delta);
  return true;
}

bool SE3LeftManifold::PlusJacobian(const double*, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 6, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>().setIdentity();
  return true;
}

bool SE3LeftManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  Eigen::Map<geometry::Vector6d> out_map(y_minus_x);
  out_map = (from_params(y) * from_params(x).inverse()).log();
  return true;
}

bool SE3LeftManifold::MinusJacobian(const double*, double* jacobian) const {
  // Consistent with PlusJacobian: Minus o Plus is the identity on delta to first order.
  Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>().setIdentity();
  return true;
}

namespace {

// d(left delta of T_cw) / d[dc; a] at x (YawTranslationManifold).
Eigen::Matrix<double, 6, 4> yaw_translation_basis(const SE3& T_cw) {
  const Eigen::Vector3d c = T_cw.inverse().translation(), z = Eigen::Vector3d::UnitZ();
  Eigen::Matrix<double, 6, 4> G = Eigen::Matrix<double, 6, 4>::Zero();
  G.topLeftCorner<3, 3>().setIdentity();
  G.block<3, 1>(0, 3) = -z.cross(c);
  G.block<3, 1>(3, 3) = z;
  return -T_cw.adjoint() * G;
}

}  // namespace

bool YawTranslationManifold::Plus(const double* x, const double* delta, double* x_plus_delta) const {
  const SE3 T_wc = from_params(x).inverse();
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(delta[3], Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const SE3 moved(Rz * T_wc.rotation(), T_wc.translation() + Eigen::Vector3d(delta[0], delta[1], delta[2]));
  const PoseParams out = to_params(moved.inverse().normalized());
  std::copy(out.begin(), out.end(), x_plus_delta);
  return true;
}

bool YawTranslationManifold::PlusJacobian(const double* x, double* jacobian) const {
  Eigen::Map<Eigen::Matrix<double, 7, 4, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.topRows<6>() = yaw_translation_basis(from_params(x));
  return true;
}

bool YawTranslationManifold::Minus(const double* y, const double* x, double* y_minus_x) const {
  const SE3 Ty = from_params(y).inverse(), Tx = from_params(x).inverse();
  const Eigen::Matrix3d dR = Ty.rotation() * Tx.rotation().transpose();
  const Eigen::Vector3d dc = Ty.translation() - Tx.translation();
  y_minus_x[0] = dc.x();
  y_minus_x[1] = dc.y();
  y_minus_x[2] = dc.z();
  y_minus_x[3] = std::atan2(dR(1, 0), dR(0, 0));
  return true;
}

bool YawTranslationManifold::MinusJacobian(const double* x, double* jacobian) const {
  // The left inverse of PlusJacobian's 6 x 4 block, so that Minus o Plus is the identity to first order.
  const Eigen::Matrix<double, 6, 4> B = yaw_translation_basis(from_params(x));
  Eigen::Map<Eigen::Matrix<double, 4, 7, Eigen::RowMajor>> J(jacobian);
  J.setZero();
  J.leftCols<6>() = (B.transpose() * B).inverse() * B.transpose();
  return true;
}

bool StereoPointCost::Evaluate(double const* const* params, double* residuals,
                               double** jacobians) const {
  const SE3 T = from_params(params[0]);
  const Eigen::Map<const Eigen::Vector3d> X(params[1]);
  Eigen::Vector3d r;
  Matrix36d Jp;
  Eigen::Matrix3d Jx;
  const bool want_pose = jacobians && jacobians[0];
  const bool want_point = jacobians && jacobians[1];
  if (!evaluate_stereo_point(cam_, T, X, obs_.measurement, obs_.has_right, &r,
                             want_pose ? &Jp : nullptr, want_point ? &Jx : nullptr)) {
    return false;  // behind the camera: Ceres rejects the step
  }
  Eigen::Map<Eigen::Vector3d> out_map(residuals);
  out_map = sqrt_info_ * r;
  if (want_pose) {
    Eigen::Map<Eigen::Matrix<double, 3, 7, Eigen::RowMajor>> J(jacobians[0]);
    J.leftCols<6>() = sqrt_info_ * Jp;
    J.col(6).setZero();
  }
  if (want_point) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> out_map(jacobians[1]);
    out_map = sqrt_info_ * Jx;
  }
  return true;
}

bool StereoLinePairCost::Evaluate(double const* const* params, double* residuals,
                                  double** jacobians) const {
  const SE3 T = from_params(params[0]);
  const Eigen::Map<const Eigen::Vector3d> Ps(params[1]);
  const Eigen::Map<const Eigen::Vector3d> Pe(params[1] + 3);
  Eigen::Vector4d r;
  Matrix46d Jp;
  Matrix43d Js, Je;
  const bool jp = jacobians && jacobians[0];
  const bool jl = jacobians && jacobians[1];
  if (!evaluate_stereo_line(cam_, T, Ps, Pe, obs_, &r, jp ? &Jp : nullptr, jl ? &Js : nullptr,
                            jl ? &Je : nullptr)) {
    return false;
  }
  const int row = right_ ? 2 : 0;
  Eigen::Map<Eigen::Vector2d> out_map(residuals);
  out_map = sqrt_info_ * r.segment<2>(row);
  if (jp) {
    Eigen::Map<Eigen::Matrix<double, 2, 7, Eigen::RowMajor>> J(jacobians[0]);
    J.leftCols<6>() = sqrt_info_ * Jp.middleRows<2>(row);
    J.col(6).setZero();
  }
  if (jl) {
    Eigen::Map<Eigen::Matrix<double, 2, 6, Eigen::RowMajor>> J(jacobians[1]);
    J.leftCols<3>() = sqrt_info_ * Js.middleRows<2>(row);
    J.rightCols<3>() = sqrt_info_ * Je.middleRows<2>(row);
  }
  return true;
}

bool RelativePoseCost::Evaluate(double const* const* params, double* residuals,
                                double** jacobians) const {
  const SE3 Ti = from_params(params[0]);
  const SE3 Tj = from_params(params[1]);
  const geometry::Vector6d e = (Z_inv_ * Ti * Tj.inverse()).log();
  Eigen::Map<geometry::Vector6d> out_map(residuals);
  out_map = sqrt_info_ * e;
  if (!jacobians) return true;
  // Left perturbation of T_i: Z^-1 exp(d) T_i T_j^-1 = exp(Ad(Z^-1) d) exp(e)
  //   => de/dd_i = J_l^-1(e) Ad(Z^-1).
  // Left perturbation of T_j: T_j^-1 -> T_j^-1 exp(-d), exp(e) exp(-d) => de/dd_j = -J_r^-1(e).
  if (jacobians[0]) {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobians[0]);
    J.leftCols<6>() = sqrt_info_ * geometry::se3_left_jacobian_inverse(e) * Z_inv_.adjoint();
    J.col(6).setZero();
  }
  if (jacobians[1]) {
    Eigen::Map<Eigen::Matrix<double, 6, 7, Eigen::RowMajor>> J(jacobians[1]);
    J.leftCols<6>() = -sqrt_info_ * geometry::se3_right_jacobian_inverse(e);
    J.col(6).setZero();
  }
  return true;
}

}  // namespace plslam::optim
