#pragma once
// The raw calibration of a stereo rig, in the layout of Kalibr's camchain.yaml, which `plslam
// calibrate` writes and `plslam run --calib` reads (Kalibr's own camchain files read as they are):
//
//   cam0:
//     camera_model: pinhole
//     distortion_model: equidistant     # or radtan (radial-tangential); "none" is radtan of zeros
//     distortion_coeffs: [k1, k2, k3, k4]   # k1 k2 p1 p2 for radtan
//     intrinsics: [fu, fv, cu, cv]      # pixels
//     resolution: [width, height]
//   cam1:
//     ... the same keys, and
//     T_cn_cnm1:                        # p_cam1 = T_cn_cnm1 * p_cam0, metres
//     - [r11, r12, r13, tx]
//     - [r21, r22, r23, ty]
//     - [r31, r32, r33, tz]
//     - [0, 0, 0, 1]
//
// Kalibr's keys that plslam does not use (rostopic, cam_overlaps, T_cam_imu, timeshift_cam_imu)
// are accepted and ignored; any other key is an error, as a typo must not pass unnoticed.
#include <filesystem>
#include <string>

#include <yaml-cpp/yaml.h>

#include "plslam/geometry/stereo_rectification.h"

namespace plslam::io {

// Whether a parsed YAML file is a camchain (it has a top-level `cam0`).
bool is_camchain(const YAML::Node& root);

// Throws InputError naming `path` and the key on a missing or malformed key, an unknown key, a
// camera model other than pinhole, cameras of different resolutions, a distortion that folds over
// inside the image, or a T_cn_cnm1 that is not a rigid transform.
geometry::RawStereoRig parse_camchain(const YAML::Node& root, const std::filesystem::path& path);
geometry::RawStereoRig read_camchain_file(const std::filesystem::path& path);

// Writes the rig atomically with `comment` (lines without '#') on top. Read back, it gives the
// same intrinsics and coefficients exactly, and the rotation to rounding (it is re-orthonormalised).
void write_camchain_file(const std::filesystem::path& path, const geometry::RawStereoRig& rig,
                         const std::string& comment);

}  // namespace plslam::io
