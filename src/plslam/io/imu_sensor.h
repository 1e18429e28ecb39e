#pragma once
// The IMU's sensor.yaml in EuRoC's imu0 layout, also the --imu-calib file of video and camera
// input: T_BS (the IMU in the body frame, 4x4 row-major), rate_hz, and the noise model's
// gyroscope_noise_density, gyroscope_random_walk, accelerometer_noise_density and
// accelerometer_random_walk (Kalibr's continuous-time units).
#include <filesystem>

#include "plslam/core/imu.h"

namespace plslam::io {

// Throws InputError naming the file for a missing file, malformed YAML, a sensor_type other than
// imu, a T_BS that is not a rigid transform, or a missing, non-numeric, non-finite or non-positive
// rate_hz or noise value.
ImuCalibration read_imu_sensor_yaml(const std::filesystem::path& path);

}  // namespace plslam::io
