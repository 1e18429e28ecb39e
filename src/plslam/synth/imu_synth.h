#pragma once
// The synthetic IMU: exact angular velocity and specific force from the camera path's analytic
// derivatives, sampled on the IMU's own clock, with the noise model of EuRoC's sensor.yaml (white
// noise densities and bias random walks) when asked, and the true states for the ground truth.
#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/core/imu.h"
#include "plslam/synth/sequence.h"

namespace plslam::synth {

struct ImuSynthOptions {
  double rate_hz = 200;
  // 0: none (exact samples, zero biases); 1: EuRoC's ADIS16448 noise with seeded non-zero biases;
  // F: those noise densities, random walks and initial biases scaled by F.
  double noise_scale = 0;
  // The camera's clock against the IMU's: an image stamped t_cam was taken when the IMU's clock read
  // t_cam - time_offset (t_cam = t_imu + time_offset).
  double time_offset = 0;
  // Samples also cover this long before the first image and after the last (IMU clock).
  double margin_s = 0.5;
};

// --imu-noise: "none", "euroc" or a non-negative factor F; InputError otherwise.
double parse_imu_noise(const std::string& text);

// The IMU's true state at one instant (the IMU frame is the body frame B).
struct ImuTrueState {
  double t = 0;  // sequence time (the camera's clock, frame i at i / fps)
  Eigen::Isometry3d T_wb = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_wb = Eigen::Vector3d::Zero();  // world frame
  Eigen::Vector3d bg = Eigen::Vector3d::Zero(), ba = Eigen::Vector3d::Zero();
};

class SyntheticImu {
 public:
  // T_bc: the left camera in the IMU frame (p_imu = T_bc * p_cam).
  SyntheticImu(const Sequence& seq, const Eigen::Isometry3d& T_bc, const ImuSynthOptions& options,
               std::uint64_t seed);

  const ImuSynthOptions& options() const { return options_; }
  ImuNoise noise() const;  // the densities the samples were drawn with (EuRoC's nominal ones if none)
  // Samples in time order; t is on the IMU's clock, which reads the sequence time minus time_offset.
  const std::vector<ImuSample>& samples() const { return samples_; }
  const Eigen::Vector3d& initial_gyro_bias() const { return bg0_; }
  const Eigen::Vector3d& initial_acc_bias() const { return ba0_; }

  // The true state at sequence time t (within the samples' span): exact pose and velocity, biases
  // interpolated between the samples'.
  ImuTrueState true_state(double t) const;
  // The ideal (noise- and bias-free) measurement at sequence time t.
  ImuSample ideal(double t) const;

 private:
  // The body's (IMU's) motion at sequence time t: T_wb = T_wc * T_cb, and its derivatives.
  struct BodyMotion {
    Eigen::Isometry3d T_wb;
    Eigen::Matrix3d R_dot;
    Eigen::Vector3d velocity, acceleration;
  };
  BodyMotion body_motion(double t) const;

  const Sequence& seq_;
  Eigen::Isometry3d T_bc_;
  ImuSynthOptions options_;
  Eigen::Vector3d bg0_ = Eigen::Vector3d::Zero(), ba0_ = Eigen::Vector3d::Zero();
  std::vector<ImuSample> samples_;
  std::vector<Eigen::Vector3d> bg_, ba_;  // the true biases at each sample
};

}  // namespace plslam::synth
