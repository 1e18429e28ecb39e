#pragma once
// Internal: the pieces every ASL/EuRoC sensor.yaml reader shares (camera and IMU). Not for use
// outside io/.
#include <filesystem>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <yaml-cpp/yaml.h>

#include "plslam/core/error.h"

namespace plslam::io::detail {

// The file as a YAML mapping, with the "%YAML:1.0" directive ASL files start with (OpenCV's, not
// valid YAML 1.2) blanked out. Throws InputError naming the file (and the line) when it is missing
// or malformed.
YAML::Node load_sensor_yaml(const std::filesystem::path& path, const char* missing = "file not found");

// `expected` finite numbers from a YAML sequence; InputError naming `key` otherwise.
std::vector<double> sensor_numbers(const YAML::Node& node, const char* key, std::size_t expected,
                                   const std::filesystem::path& path);

// T_BS (rows, cols, data: 16 numbers row-major), which must be a rigid transform.
Eigen::Isometry3d parse_sensor_T_BS(const YAML::Node& root, const std::filesystem::path& path);

// yaml-cpp throws on a value of the wrong shape (a list where a string is expected, a key on a
// scalar): that is the file's problem, reported as one line naming it (found by fuzzing,
// tests/fuzz/corpus/euroc_sensor/).
template <class F>
auto with_yaml_errors_as_input_errors(const std::filesystem::path& path, F&& body) {
  try {
    return body();
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), "malformed sensor.yaml: " + e.msg);
  }
}

}  // namespace plslam::io::detail
