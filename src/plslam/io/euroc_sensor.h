#pragma once
// The ASL/EuRoC camera sensor.yaml (also TUM-VI's and Kalibr's camchain fields): a pinhole
// projection with radial-tangential or equidistant (Kannala-Brandt fisheye) distortion, and T_BS,
// the pose of the sensor in the body frame (p_body = T_BS * p_sensor).
#include <array>
#include <filesystem>
#include <string>

#include <Eigen/Geometry>

#include "plslam/core/types.h"
#include "plslam/geometry/lens_model.h"

namespace plslam::io {

struct EurocCameraSensor {
  Eigen::Isometry3d T_BS = Eigen::Isometry3d::Identity();
  int width = 0;
  int height = 0;
  double fu = 0, fv = 0, cu = 0, cv = 0;
  geometry::LensModel distortion_model = geometry::LensModel::kRadialTangential;
  std::array<double, 4> distortion{};  // k1, k2, p1, p2 (radial-tangential) or k1..k4 (equidistant)
  double rate_hz = 0;

  geometry::LensCamera lens() const { return {distortion_model, width, height, fu, fv, cu, cv, distortion}; }
};

// Throws InputError naming the file on a missing file, malformed YAML, missing keys, wrong sizes,
// NaNs or a T_BS that is not a rigid transform.
EurocCameraSensor read_euroc_camera_yaml(const std::filesystem::path& path);

// Writes a camera's sensor.yaml atomically, as the ASL/EuRoC layout has it, with `comment` in its
// comment field; read back by read_euroc_camera_yaml it gives the same numbers.
void write_euroc_camera_yaml(const std::filesystem::path& path, const EurocCameraSensor& sensor,
                             const std::string& comment);

// Reads only T_BS, for files such as a body-to-camera argument of `plslam eval`.
Eigen::Isometry3d read_euroc_T_BS(const std::filesystem::path& path);

// Re-expresses a body-frame trajectory (T_world_body) as the trajectory of a sensor mounted at
// T_BS: T_world_sensor = T_world_body * T_BS.
Trajectory body_to_sensor(const Trajectory& body, const Eigen::Isometry3d& T_BS);

}  // namespace plslam::io
