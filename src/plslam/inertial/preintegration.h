#pragma once
// On-manifold IMU preintegration (Forster, Carlone, Dellaert, Scaramuzza, "On-Manifold
// Preintegration for Real-Time Visual-Inertial Odometry", TRO 2017): the IMU's motion between two
// times t_i < t_j, in the body frame at t_i and independent of the states at t_i and t_j, so that
// an optimiser can move those states without integrating again. Integrated with the midpoint
// rule (midpoint_step.h) at a fixed linearisation bias; for a nearby bias the deltas are
// corrected to first order, and re-integrated from the stored samples once it moved far.
//
// With R, v, p the body's rotation, velocity and position in the world at t_i and t_j, g the
// world's gravity and dt = t_j - t_i:
//   delta_R = R_i' R_j,  delta_v = R_i' (v_j - v_i - g dt),
//   delta_p = R_i' (p_j - p_i - v_i dt - g dt^2 / 2).
#include <span>
#include <vector>

#include <Eigen/Core>

#include "plslam/core/imu.h"
#include "plslam/geometry/se3.h"
#include "plslam/inertial/imu_bias.h"
#include "plslam/inertial/midpoint_step.h"

namespace plslam::inertial {

// How far the bias may move from the linearisation bias before the first-order correction gives
// way to re-integration. The deltas are linear in the accelerometer bias; what the correction
// misses comes from the gyro bias (and its cross term with the accelerometer's). With EuRoC's IMU,
// over 0.5 s of a brisk hand-held motion, changes just below both thresholds leave the corrected
// deltas off by <= 2% of their standard deviations (tests/inertial), ~10% over 1 s.
struct ReintegrationThresholds {
  double gyro = 1e-2;  // rad/s, on the norm of the change of bg
  double acc = 1e-1;   // m/s^2, on the norm of the change of ba
};

class Preintegration {
 public:
  // `samples`: strictly increasing times, at least one at or before t_i and one at or after t_j
  // (an ImuData's samples, or any part of them). Interval ends between samples get linearly
  // interpolated measurements. Throws std::invalid_argument when t_i >= t_j, the samples do not
  // cover [t_i, t_j] or are not increasing, or a noise density is negative.
  Preintegration(std::span<const ImuSample> samples, double t_i, double t_j,
                 const ImuBias& linearisation_bias, const ImuNoise& noise);

  double t_i() const { return samples_.front().t; }
  double t_j() const { return samples_.back().t; }
  double dt() const { return t_j() - t_i(); }
  const ImuBias& linearisation_bias() const { return bias_; }
  const ImuNoise& noise() const { return noise_; }
  // The integrated samples: the interval's ends (interpolated) and the samples strictly inside.
  const std::vector<ImuSample>& samples() const { return samples_; }

  // The deltas at the linearisation bias.
  const Eigen::Matrix3d& delta_R() const { return deltas_.R; }
  const Eigen::Vector3d& delta_v() const { return deltas_.v; }
  const Eigen::Vector3d& delta_p() const { return deltas_.p; }

  // First-order effect of a bias change (dbg, dba) on the deltas:
  //   delta_R(b + db) ~= delta_R Exp(dR_dbg dbg),  delta_v(b + db) ~= delta_v + dv_dbg dbg + dv_dba
  //   dba,
  // and likewise for delta_p. bias_jacobian() holds them all: rows [dphi; dv; dp], columns
  // [dbg; dba] (its top right block, dR_dba, is zero).
  const Matrix96d& bias_jacobian() const { return bias_jacobian_; }
  Eigen::Matrix3d dR_dbg() const { return bias_jacobian_.block<3, 3>(0, 0); }
  Eigen::Matrix3d dv_dbg() const { return bias_jacobian_.block<3, 3>(3, 0); }
  Eigen::Matrix3d dv_dba() const { return bias_jacobian_.block<3, 3>(3, 3); }
  Eigen::Matrix3d dp_dbg() const { return bias_jacobian_.block<3, 3>(6, 0); }
  Eigen::Matrix3d dp_dba() const { return bias_jacobian_.block<3, 3>(6, 3); }

  // The deltas for another bias, corrected to first order (Forster's eq. 44).
  Eigen::Matrix3d corrected_delta_R(const ImuBias& b) const;
  Eigen::Vector3d corrected_delta_v(const ImuBias& b) const;
  Eigen::Vector3d corrected_delta_p(const ImuBias& b) const;

  // Whether `b` is too far from the linearisation bias for the first-order correction.
  bool bias_moved_far(const ImuBias& b, const ReintegrationThresholds& thresholds = {}) const;
  // Integrates the stored samples again, linearised at `b`.
  void reintegrate(const ImuBias& b);

  // Covariance of the deltas' errors [dphi; dv; dp] (delta_R_true = delta_R Exp(dphi), ...) from
  // the white measurement noise: each step's mean reading carries noise of variance sigma^2 / dt,
  // sigma being the continuous-time density, dt the step's length, independent between steps.
  // Readings with independent noise per sample make neighbouring steps share noise; against
  // them this is slightly conservative (variances ~3% high on average at 40 steps).
  const Matrix9d& covariance() const { return covariance_; }
  // Covariance of the bias change over [t_i, t_j], [dbg; dba], from the bias random walks.
  geometry::Matrix6d bias_random_walk_covariance() const;

 private:
  void integrate();

  std::vector<ImuSample> samples_;
  ImuBias bias_;
  ImuNoise noise_;
  PreintegratedDeltas deltas_;
  Matrix96d bias_jacobian_;
  Matrix9d covariance_;
};

}  // namespace plslam::inertial
