#pragma once
// The paper's stereo line reprojection error (its eq. 8, with the right-image term written in
// right-image pixels). For a 3D segment with world endpoints P_s, P_e and camera points
// X = T_cw P, the 4 residuals are signed pixel distances
//   r0 = l_L . (u_l(X_s), v(X_s), 1)     r1 = l_L . (u_l(X_e), v(X_e), 1)
//   r2 = l_R . (u_r(X_s), v(X_s), 1)     r3 = l_R . (u_r(X_e), v(X_e), 1)
// with u_r = u_l - bf/z, l_L / l_R the observed left / right image lines (unit (a, b)).
// Analytic Jacobians: docs/line_reprojection_jacobians.md, section 3.
#include <Eigen/Core>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/observations.h"

namespace plslam::optim {

using Matrix46d = Eigen::Matrix<double, 4, 6>;
using Matrix43d = Eigen::Matrix<double, 4, 3>;

namespace detail {
// Row vector d(l . (u, v, 1))/d(X_c) for the left (right = false) or right image line.
inline Eigen::RowVector3d line_point_gradient(const geometry::StereoCamera& cam,
                                              const Eigen::Vector3d& l, const Eigen::Vector3d& Xc,
                                              bool right) {
  const double iz = 1.0 / Xc.z();
  const double a = l(0) * cam.fx(), b = l(1) * cam.fy();
  const double xz = right ? a * Xc.x() - l(0) * cam.bf() : a * Xc.x();
  return {a * iz, b * iz, -(xz + b * Xc.y()) * iz * iz};
}
}  // namespace detail

// Returns false (outputs untouched) when an endpoint is not in front of the camera. J_pose is
// w.r.t. the left perturbation [rho; phi] of T_cw, J_start / J_end w.r.t. the world endpoints
// (rows 1, 3 of J_start and rows 0, 2 of J_end are zero). Null Jacobian pointers are skipped.
// The 4 residuals at camera endpoints with positive depth.
inline Eigen::Vector4d stereo_line_residual_at(const geometry::StereoCamera& cam,
                                               const Eigen::Vector3d& Xs, const Eigen::Vector3d& Xe,
                                               const StereoLineObservation& obs) {
  const Eigen::Vector3d ps = cam.project_stereo(Xs);
  const Eigen::Vector3d pe = cam.project_stereo(Xe);
  const Eigen::Vector3d& lL = obs.left_line;
  const Eigen::Vector3d& lR = obs.right_line;
  return {lL(0) * ps(0) + lL(1) * ps(1) + lL(2), lL(0) * pe(0) + lL(1) * pe(1) + lL(2),
          lR(0) * ps(2) + lR(1) * ps(1) + lR(2), lR(0) * pe(2) + lR(1) * pe(1) + lR(2)};
}

inline bool evaluate_stereo_line(const geometry::StereoCamera& cam, const geometry::SE3& T_cw,
                                 const Eigen::Vector3d& Ps, const Eigen::Vector3d& Pe,
                                 const StereoLineObservation& obs, Eigen::Vector4d* r,
                                 Matrix46d* J_pose, Matrix43d* J_start, Matrix43d* J_end) {
  const Eigen::Vector3d Xs = T_cw * Ps;
  const Eigen::Vector3d Xe = T_cw * Pe;
  if (!(Xs.z() > 0.0) || !(Xe.z() > 0.0)) return false;
  *r = stereo_line_residual_at(cam, Xs, Xe, obs);
  const Eigen::Vector3d& lL = obs.left_line;
  const Eigen::Vector3d& lR = obs.right_line;
  if (!J_pose && !J_start && !J_end) return true;
  Eigen::Matrix<double, 4, 3> Gs = Eigen::Matrix<double, 4, 3>::Zero();  // d r / d X_s
  Eigen::Matrix<double, 4, 3> Ge = Eigen::Matrix<double, 4, 3>::Zero();  // d r / d X_e
  Gs.row(0) = detail::line_point_gradient(cam, lL, Xs, false);
  Ge.row(1) = detail::line_point_gradient(cam, lL, Xe, false);
  Gs.row(2) = detail::line_point_gradient(cam, lR, Xs, true);
  Ge.row(3) = detail::line_point_gradient(cam, lR, Xe, true);
  if (J_pose) {
    // d(X)/d(delta) = [I, -hat(X)] for each endpoint.
    J_pose->leftCols<3>() = Gs + Ge;
    J_pose->rightCols<3>() = -Gs * geometry::hat(Xs) - Ge * geometry::hat(Xe);
  }
  const Eigen::Matrix3d& R = T_cw.rotation();
  if (J_start) *J_start = Gs * R;
  if (J_end) *J_end = Ge * R;
  return true;
}

// Each endpoint enters two residuals, one per image (rows 0, 2 the start, rows 1, 3 the end), with
// d r / d X = G_x [I, -hat(X_x)] for the pose and G_x R for the endpoint, G_x the 2x3 stack of its
// left and right line_point_gradient. So an endpoint is a point observation with
//   B_x = G_x' diag(w_left, w_right) G_x,   a_x = G_x' diag(w_left, w_right) (r_left, r_right)
// (add_pose_normal_equations), and the line's landmark block is block diagonal (start, end).
// w = (w_left, w_right): the weights of the two image pairs. Index 0 start, 1 end.
inline void stereo_line_weighted_normal(const geometry::StereoCamera& cam, const Eigen::Vector3d& Xs,
                                        const Eigen::Vector3d& Xe, const StereoLineObservation& obs,
                                        const Eigen::Vector4d& r, const Eigen::Vector2d& w,
                                        Eigen::Matrix3d B[2], Eigen::Vector3d a[2]) {
  for (int x = 0; x < 2; ++x) {
    const Eigen::Vector3d& X = x == 0 ? Xs : Xe;
    const Eigen::Vector3d gl = detail::line_point_gradient(cam, obs.left_line, X, false).transpose();
    const Eigen::Vector3d gr = detail::line_point_gradient(cam, obs.right_line, X, true).transpose();
    const Eigen::Vector3d wgl = w(0) * gl, wgr = w(1) * gr;
    B[x].noalias() = wgl * gl.transpose();
    B[x].noalias() += wgr * gr.transpose();
    a[x] = wgl * r(x) + wgr * r(2 + x);
  }
}

}  // namespace plslam::optim
