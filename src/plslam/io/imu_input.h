#pragma once
// An input's IMU put together from its two files (samples and sensor.yaml), placed against the
// rectified left camera, and cut to the frames the run reads.
#include <filesystem>
#include <vector>

#include <Eigen/Geometry>

#include "plslam/core/imu.h"

namespace plslam::io {

// IMU time kept on each side of the selected frames: enough to integrate from just before the
// first frame to just after the last, little enough that memory does not grow with the recording.
inline constexpr double kImuMarginS = 0.5;

// read_imu_csv(csv) and read_imu_sensor_yaml(yaml), with T_imu_cam = T_BS^-1 * T_body_cam, where
// T_body_cam is the rectified left camera in the body frame of the yaml's T_BS. Warns when the
// measured rate is more than 10 % off the nominal rate_hz.
ImuData read_imu(const std::filesystem::path& csv, const std::filesystem::path& yaml,
                 const Eigen::Isometry3d& T_body_cam);

// Throws InputError(csv, ...) unless the samples reach from at or before t_first to at or after
// t_last (the first and last selected frames, on the samples' clock); then keeps only the samples
// within kImuMarginS of that span.
void keep_imu_span(ImuData& imu, double t_first, double t_last, const std::filesystem::path& csv);

// Median sample rate in Hz; 0 with fewer than two samples.
double median_rate_hz(const std::vector<ImuSample>& samples);

}  // namespace plslam::io
