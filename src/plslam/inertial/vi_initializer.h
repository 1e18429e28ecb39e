#pragma once
// Visual-inertial initialisation from the first keyframes of stereo tracking. Stereo fixes the
// scale, so what the IMU adds is unknown: the direction of gravity in the visual world, the
// keyframes' velocities, and the gyro and accelerometer biases. They are estimated together as an
// inertial-only maximum a posteriori problem (as ORB-SLAM3's inertial-only step, but with the
// keyframe positions free under a prior of the tracker's accuracy, the rotations held fixed):
// preintegrated IMU residuals between consecutive keyframes plus weak zero-mean bias priors,
// solved with Ceres and re-linearised at the new bias.
//
// An initialisation is accepted only when it is observable: the marginal standard deviation of the
// gravity direction must be small. Without rotation the accelerometer bias and the tilt of gravity
// cannot be told apart (both shift the measured specific force the same way), and then the answer
// is a refusal, not a guess; the gyro bias, observable from rotation alone, is still reported.
#include <span>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/core/imu.h"
#include "plslam/inertial/imu_bias.h"

namespace plslam::inertial {

struct ViKeyframe {
  double t = 0;                                          // seconds, the images' clock
  Eigen::Isometry3d T_wc = Eigen::Isometry3d::Identity();  // left camera in the visual world (metric)
};

struct ViInitOptions {
  int min_keyframes = 5;
  double min_span_s = 0.5;
  // Accepted when the gravity direction's marginal standard deviation is at most this.
  double max_gravity_sigma_deg = 0.2;  // 2.5 sigma = 0.5 deg
  // ... and the whitened residuals' RMS at most this (the IMU and the poses agree).
  double max_rms_residual = 3.0;
  // Zero-mean priors on the biases (standard deviations): they keep the problem well posed
  // without motion, and are weak against what a moving IMU tells.
  double gyro_bias_prior = 0.1;  // rad/s
  double acc_bias_prior = 0.5;   // m/s^2
  int max_relinearisations = 3;
  // The keyframe poses' own errors (per axis, standard deviations): the positions move under a
  // prior of this width (0: held fixed), the rotations' errors are added to the residuals' weights.
  // Stereo tracking of the renders leaves 3-5 mm and about 1 mrad over the first 2 s.
  double pose_position_sigma = 0.004;  // m
  double pose_rotation_sigma = 1e-3;   // rad
  // ... and the positions' errors grow with the path travelled since the window's first keyframe
  // (added in quadrature). The street render at 5 m/s: 1.6 cm rms, 3.4 cm at most over a window of
  // 25 m; with 4 mm alone, gravity came out 1.45 deg off at a claimed sigma of 0.17 deg.
  double pose_position_sigma_per_m = 0.001;

  void validate() const;  // std::invalid_argument on a bad value
};

struct ViInitResult {
  bool accepted = false;
  std::string reason;  // why it was refused (empty when accepted)
  bool solved = false;  // the estimates below are filled in (also when refused for being unobservable)
  int keyframes = 0;
  double span_s = 0;
  double rotation_deg = 0;  // largest rotation between the window's first keyframe and another
  Eigen::Vector3d gravity_direction = Eigen::Vector3d(0, 0, -1);  // unit, visual world: where gravity pulls
  double gravity_sigma_deg = 0;
  ImuBias bias;
  Eigen::Vector3d gyro_bias_sigma = Eigen::Vector3d::Zero(), acc_bias_sigma = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3d> velocities;  // of the IMU, visual world, one per keyframe
  double rms_residual = 0;                  // whitened IMU residuals
  double solve_ms = 0;

  // The rotation by the smallest angle that takes the visual world to a gravity-aligned one
  // (z up): R_gw * gravity_direction = (0, 0, -1).
  Eigen::Matrix3d R_gw() const;
};

// `keyframes` in time order; `imu` must cover them. Never throws on what the data says (too few
// keyframes, an IMU gap): that is a refusal with its reason.
ViInitResult initialize_visual_inertial(std::span<const ViKeyframe> keyframes, const ImuData& imu,
                                        const ViInitOptions& options = {});

}  // namespace plslam::inertial
