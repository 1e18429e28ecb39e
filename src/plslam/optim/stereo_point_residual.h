#pragma once
// Stereo point reprojection residual r = project_stereo(T_cw X_w) - z (3 rows: u_l, v, u_r) and
// its analytic Jacobians. Derivation: docs/line_reprojection_jacobians.md, section 2.
#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"

namespace plslam::optim {

using Matrix36d = Eigen::Matrix<double, 3, 6>;

// Returns false (outputs untouched) when the point is not in front of the camera. Without a
// right match the third row of r and of both Jacobians is zero. J_pose is w.r.t. the left
// perturbation delta = [rho; phi] of T_cw; J_point w.r.t. X_w. Null Jacobian pointers are skipped.
inline bool evaluate_stereo_point(const geometry::StereoCamera& cam, const geometry::SE3& T_cw,
                                  const Eigen::Vector3d& Xw, const Eigen::Vector3d& z,
                                  bool has_right, Eigen::Vector3d* r, Matrix36d* J_pose,
                                  Eigen::Matrix3d* J_point) {
  const Eigen::Vector3d Xc = T_cw * Xw;
  if (!(Xc.z() > 0.0)) return false;
  const double iz = 1.0 / Xc.z();
  const double x = Xc.x(), y = Xc.y();
  const double fx = cam.fx(), fy = cam.fy(), bf = cam.bf();
  const double ul = fx * x * iz + cam.cx();
  (*r)(0) = ul - z(0);
  (*r)(1) = fy * y * iz + cam.cy() - z(1);
  (*r)(2) = has_right ? ul - bf * iz - z(2) : 0.0;
  if (!J_pose && !J_point) return true;
  // d(projection)/d(X_c)
  Eigen::Matrix3d A;
  A << fx * iz, 0.0, -fx * x * iz * iz,  //
      0.0, fy * iz, -fy * y * iz * iz,    //
      fx * iz, 0.0, -(fx * x - bf) * iz * iz;
  if (!has_right) A.row(2).setZero();
  if (J_pose) {
    // d(X_c)/d(delta) = [I, -hat(X_c)]
    J_pose->leftCols<3>() = A;
    J_pose->rightCols<3>() = -A * geometry::hat(Xc);
  }
  if (J_point) *J_point = A * T_cw.rotation();
  return true;
}

}  // namespace plslam::optim
