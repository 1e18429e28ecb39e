#pragma once
// EuRoC ground truth describes the body (IMU) frame; a camera estimate needs camera poses:
// T_w_cam = T_w_body * T_BS, with T_BS the camera's extrinsics from its sensor.yaml.
#include <filesystem>

#include "plslam/core/types.h"

namespace plslam::eval {

// Reads T_BS (4x4, row-major `data`) from an EuRoC sensor.yaml. Throws InputError when the file
// or the entry is missing, or the matrix is not a rigid transform.
Eigen::Isometry3d read_euroc_T_BS(const std::filesystem::path& sensor_yaml);

// Right-multiplies every pose by T_BS.
Trajectory body_to_camera(const Trajectory& body, const Eigen::Isometry3d& T_BS);

}  // namespace plslam::eval
