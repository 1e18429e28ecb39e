#pragma once
// Stereo point reprojection residual r = project_stereo(T_cw X_w) - z (3 rows: u_l, v, u_r) and
// its analytic Jacobians. Derivation: docs/line_reprojection_jacobians.md, section 2.
#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"

namespace plslam::optim {

using Matrix36d = Eigen::Matrix<double, 3, 6>;

// d(projection)/d(X_c) at a camera point with X_c.z() > 0 (third row zero without a right match).
inline Eigen::Matrix3d stereo_point_projection_jacobian(const geometry::StereoCamera& cam,
                                                        const Eigen::Vector3d& Xc, bool has_right) {
  const double iz = 1.0 / Xc.z();
  const double x = Xc.x(), y = Xc.y();
  const double fx = cam.fx(), fy = cam.fy(), bf = cam.bf();
  Eigen::Matrix3d A;
  A << fx * iz, 0.0, -fx * x * iz * iz,  //
      0.0, fy * iz, -fy * y * iz * iz,    //
      fx * iz, 0.0, -(fx * x - bf) * iz * iz;
  if (!has_right) A.row(2).setZero();
  return A;
}

// The residual at a camera point with X_c.z() > 0.
inline Eigen::Vector3d stereo_point_residual_at(const geometry::StereoCamera& cam,
                                                const Eigen::Vector3d& Xc, const Eigen::Vector3d& z,
                                                bool has_right) {
  const double iz = 1.0 / Xc.z();
  const double ul = cam.fx() * Xc.x() * iz + cam.cx();
  return {ul - z(0), cam.fy() * Xc.y() * iz + cam.cy() - z(1),
          has_right ? ul - cam.bf() * iz - z(2) : 0.0};
}

// Returns false (outputs untouched) when the point is not in front of the camera. Without a
// right match the third row of r and of both Jacobians is zero. J_pose is w.r.t. the left
// perturbation delta = [rho; phi] of T_cw; J_point w.r.t. X_w. Null Jacobian pointers are skipped.
inline bool evaluate_stereo_point(const geometry::StereoCamera& cam, const geometry::SE3& T_cw,
                                  const Eigen::Vector3d& Xw, const Eigen::Vector3d& z,
                                  bool has_right, Eigen::Vector3d* r, Matrix36d* J_pose,
                                  Eigen::Matrix3d* J_point) {
  const Eigen::Vector3d Xc = T_cw * Xw;
  if (!(Xc.z() > 0.0)) return false;
  *r = stereo_point_residual_at(cam, Xc, z, has_right);
  if (!J_pose && !J_point) return true;
  const Eigen::Matrix3d A = stereo_point_projection_jacobian(cam, Xc, has_right);
  if (J_pose) {
    // d(X_c)/d(delta) = [I, -hat(X_c)]
    J_pose->leftCols<3>() = A;
    J_pose->rightCols<3>() = -A * geometry::hat(Xc);
  }
  if (J_point) *J_point = A * T_cw.rotation();
  return true;
}

// B = w A'A and a = w A'r for A = stereo_point_projection_jacobian(cam, Xc, has_right), from A's
// zeros (A(0,1) = A(1,0) = A(2,1) = 0, A(2,0) = A(0,0)): B(0,1) = 0, a dozen products in all.
inline void stereo_point_weighted_normal(const geometry::StereoCamera& cam, const Eigen::Vector3d& Xc,
                                         const Eigen::Vector3d& r, bool has_right, double w,
                                         Eigen::Matrix3d* B, Eigen::Vector3d* a) {
  const double iz = 1.0 / Xc.z();
  const double fx = cam.fx(), fy = cam.fy();
  const double p = fx * iz, s = fy * iz;  // A(0,0) = A(2,0), A(1,1)
  const double q0 = -fx * Xc.x() * iz * iz, q1 = -fy * Xc.y() * iz * iz;
  const double q2 = has_right ? -(fx * Xc.x() - cam.bf()) * iz * iz : 0.0;
  const double p2 = has_right ? p : 0.0;
  const double b00 = w * (p * p + p2 * p2), b02 = w * (p * q0 + p2 * q2);
  const double b11 = w * (s * s), b12 = w * (s * q1);
  const double b22 = w * (q0 * q0 + q1 * q1 + q2 * q2);
  *B << b00, 0.0, b02,  //
      0.0, b11, b12,    //
      b02, b12, b22;
  *a << w * (p * r(0) + p2 * r(2)), w * (s * r(1)), w * (q0 * r(0) + q1 * r(1) + q2 * r(2));
}

// Normal equations of one point observation without forming J_pose: with J_pose = A [I, -hat(X_c)]
// and B = w A'A (symmetric), a = w A'r (the camera-frame gradient),
//   w J_pose' J_pose = [B, -B hat; hat B, -hat B hat],   w J_pose' r = [a; X_c x a],
// i.e. a handful of cross products instead of a 6x3 by 3x6 product. Adds them to H (6x6) and g (6).
template <class HBlock, class GBlock>
inline void add_pose_normal_equations(const Eigen::Matrix3d& B, const Eigen::Vector3d& a,
                                      const Eigen::Vector3d& Xc, HBlock&& H, GBlock&& g) {
  Eigen::Matrix3d D;  // hat(X_c) B
  for (int j = 0; j < 3; ++j) D.col(j) = Xc.cross(B.col(j));
  Eigen::Matrix3d E;  // -hat(X_c) B hat(X_c) = D hat(X_c)', symmetric: column i = X_c x D.row(i)'
  for (int i = 0; i < 3; ++i) E.col(i) = Xc.cross(D.row(i).transpose());
  H.template topLeftCorner<3, 3>() += B;
  H.template topRightCorner<3, 3>() += D.transpose();
  H.template bottomLeftCorner<3, 3>() += D;
  H.template bottomRightCorner<3, 3>() += E;
  g.template head<3>() += a;
  g.template tail<3>() += Xc.cross(a);
}

}  // namespace plslam::optim
