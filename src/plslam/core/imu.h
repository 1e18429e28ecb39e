#pragma once
// Inertial measurements and the IMU's calibration, as the readers give them to every stage.
// Conventions (those of EuRoC's imu0): the IMU frame S is the sensor's own; gyro is the angular
// velocity of S against the world, in S (rad/s); acc is the specific force in S (m/s^2): the
// acceleration minus gravity, so that a resting IMU reads +9.81 m/s^2 upwards.
#include <optional>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace plslam {

struct ImuSample {
  double t = 0;  // seconds, on the images' clock
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();
};

// The continuous-time noise model of Kalibr and EuRoC's sensor.yaml: white noise densities and
// bias random walks.
struct ImuNoise {
  double gyro_noise_density = 0;  // rad / s / sqrt(Hz)
  double gyro_random_walk = 0;    // rad / s^2 / sqrt(Hz)
  double acc_noise_density = 0;   // m / s^2 / sqrt(Hz)
  double acc_random_walk = 0;     // m / s^3 / sqrt(Hz)
};

// EuRoC's ADIS16448 (the values of its imu0/sensor.yaml).
inline constexpr ImuNoise kEurocAdis16448Noise{1.6968e-04, 1.9393e-05, 2.0000e-3, 3.0000e-3};

// Standard gravity, m/s^2 (the world's z axis points up once gravity is known).
inline constexpr double kGravity = 9.81;

struct ImuCalibration {
  // The IMU in the dataset's body frame (p_body = T_BS * p_imu), as its sensor.yaml says.
  Eigen::Isometry3d T_BS = Eigen::Isometry3d::Identity();
  double rate_hz = 0;  // nominal
  ImuNoise noise;
};

// An input's IMU: its calibration, its samples in time order (strictly increasing t, finite), and
// where the rectified left camera sits in the IMU frame (p_imu = T_imu_cam * p_cam).
struct ImuData {
  ImuCalibration calibration;
  Eigen::Isometry3d T_imu_cam = Eigen::Isometry3d::Identity();
  std::vector<ImuSample> samples;
};

}  // namespace plslam
