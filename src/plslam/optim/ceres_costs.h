#pragma once
// Analytic Ceres cost functions and the SE(3) manifold used by bundle adjustment and the pose
// graph. A pose parameter block holds 7 doubles [t_x t_y t_z q_x q_y q_z q_w] of T_cw. The
// manifold's Plus is the left update T <- exp(delta) T; its PlusJacobian is [I_6; 0], and every
// cost writes its Jacobian w.r.t. delta into the first 6 of the 7 ambient columns (zero in the
// last), so that Ceres' product J_ambient * PlusJacobian equals the left-perturbation Jacobian.
#include <array>

#include <ceres/manifold.h>
#include <ceres/sized_cost_function.h>

#include "plslam/geometry/se3.h"
#include "plslam/geometry/stereo_camera.h"
#include "plslam/optim/observations.h"

namespace plslam::optim {

using PoseParams = geometry::PoseParams;
inline PoseParams to_params(const geometry::SE3& T) { return geometry::to_pose_params(T); }
inline geometry::SE3 from_params(const double* p) { return geometry::from_pose_params(p); }

class SE3LeftManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 6; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// The same pose block moved only by a yaw about the world's z axis and a world translation, the
// 4 directions a visual-inertial map leaves open (roll and pitch are observable from gravity):
// T_wc <- [Rz(a) R_wc, c + dc], tangent [dc (3, world); a]. PlusJacobian is the left delta of T_cw
// per tangent direction in the first 6 ambient rows, as SE3LeftManifold's convention wants the
// costs' Jacobians: [-Ad(T_cw) [I, -e_z x c; 0, e_z]; 0].
class YawTranslationManifold final : public ceres::Manifold {
 public:
  int AmbientSize() const override { return 7; }
  int TangentSize() const override { return 4; }
  bool Plus(const double* x, const double* delta, double* x_plus_delta) const override;
  bool PlusJacobian(const double* x, double* jacobian) const override;
  // [c_y - c_x; the yaw of R_wc_y R_wc_x'], the inverse of Plus where y differs from x by such a move.
  bool Minus(const double* y, const double* x, double* y_minus_x) const override;
  bool MinusJacobian(const double* x, double* jacobian) const override;
};

// Whitened stereo point residual sqrt(info) * (project_stereo(T X) - z); blocks: pose, point.
class StereoPointCost final : public ceres::SizedCostFunction<3, 7, 3> {
 public:
  StereoPointCost(const geometry::StereoCamera& cam, const StereoPointObservation& obs,
                  double sqrt_info)
      : cam_(cam), obs_(obs), sqrt_info_(sqrt_info) {}
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override;

 private:
  geometry::StereoCamera cam_;
  StereoPointObservation obs_;
  double sqrt_info_;
};

// One image's pair of the stereo line residual (rows 0-1: left image, rows 2-3: right image),
// whitened by sqrt(info); blocks: pose, endpoints [P_s; P_e] (one 6-vector, so that a line is a
// single block the Schur complement can eliminate).
class StereoLinePairCost final : public ceres::SizedCostFunction<2, 7, 6> {
 public:
  StereoLinePairCost(const geometry::StereoCamera& cam, const StereoLineObservation& obs,
                     bool right_image, double sqrt_info)
      : cam_(cam), obs_(obs), right_(right_image), sqrt_info_(sqrt_info) {}
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override;

 private:
  geometry::StereoCamera cam_;
  StereoLineObservation obs_;
  bool right_;
  double sqrt_info_;
};

// Relative-pose edge between T_i and T_j (both T_cw): e = log(Z^-1 T_i T_j^-1), where
// Z = T_i T_j^-1 is the measured relative pose, whitened by an upper-triangular L with
// L' L = information. Blocks: pose i, pose j.
class RelativePoseCost final : public ceres::SizedCostFunction<6, 7, 7> {
 public:
  RelativePoseCost(const geometry::SE3& Z_ij, const geometry::Matrix6d& sqrt_information)
      : Z_inv_(Z_ij.inverse()), sqrt_info_(sqrt_information) {}
  bool Evaluate(double const* const* params, double* residuals, double** jacobians) const override;

 private:
  geometry::SE3 Z_inv_;
  geometry::Matrix6d sqrt_info_;
};

}  // namespace plslam::optim
