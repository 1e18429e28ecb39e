#include "plslam/io/imu_sensor.h"

#include <cmath>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/io/sensor_yaml.h"

namespace plslam::io {
namespace {

// A scalar that must be a finite number above zero (a rate, a noise density).
double positive_number(const YAML::Node& root, const char* key, const std::filesystem::path& path) {
  const YAML::Node node = root[key];
  if (!node) throw InputError(path.string(), fmt::format("missing '{}'", key));
  double x = 0;
  if (!node.IsScalar()) throw InputError(path.string(), fmt::format("'{}' is not a number", key));
  try {
    x = node.as<double>();
  } catch (const YAML::Exception&) {
    throw InputError(path.string(), fmt::format("'{}' is not a number", key));
  }
  if (!std::isfinite(x)) throw InputError(path.string(), fmt::format("'{}' must be finite, got {}", key, x));
  if (!(x > 0)) throw InputError(path.string(), fmt::format("'{}' must be positive, got {}", key, x));
  return x;
}

ImuCalibration parse_imu_yaml(const YAML::Node& root, const std::filesystem::path& path) {
  // A camera's sensor.yaml given for the IMU's would fail below on a missing key; say why instead.
  if (const YAML::Node type = root["sensor_type"]; type && type.IsScalar() && type.Scalar() != "imu") {
    throw InputError(path.string(), "sensor_type is not 'imu'");
  }
  ImuCalibration c;
  c.T_BS = detail::parse_sensor_T_BS(root, path);
  c.rate_hz = positive_number(root, "rate_hz", path);
  c.noise.gyro_noise_density = positive_number(root, "gyroscope_noise_density", path);
  c.noise.gyro_random_walk = positive_number(root, "gyroscope_random_walk", path);
  c.noise.acc_noise_density = positive_number(root, "accelerometer_noise_density", path);
  c.noise.acc_random_walk = positive_number(root, "accelerometer_random_walk", path);
  return c;
}

}  // namespace

ImuCalibration read_imu_sensor_yaml(const std::filesystem::path& path) {
  const YAML::Node root = detail::load_sensor_yaml(path);
  return detail::with_yaml_errors_as_input_errors(path, [&] { return parse_imu_yaml(root, path); });
}

}  // namespace plslam::io
