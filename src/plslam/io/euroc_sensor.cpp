#include "plslam/io/euroc_sensor.h"

#include <cmath>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "plslam/core/error.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/sensor_yaml.h"

namespace plslam::io {
namespace {

namespace fs = std::filesystem;
using detail::parse_sensor_T_BS;
using detail::sensor_numbers;
using detail::with_yaml_errors_as_input_errors;

EurocCameraSensor parse_camera_yaml(const YAML::Node& root, const fs::path& path) {
  EurocCameraSensor s;
  s.T_BS = parse_sensor_T_BS(root, path);
  const auto res = sensor_numbers(root["resolution"], "resolution", 2, path);
  if (!(res[0] >= 1 && res[0] <= 100000 && res[1] >= 1 && res[1] <= 100000) || res[0] != std::floor(res[0]) ||
      res[1] != std::floor(res[1]))
    throw InputError(path.string(), "resolution must be two whole numbers in [1, 100000]");
  s.width = static_cast<int>(res[0]);
  s.height = static_cast<int>(res[1]);
  if (root["camera_model"] && root["camera_model"].as<std::string>() != "pinhole") {
    throw InputError(path.string(), "unsupported camera_model '" + root["camera_model"].as<std::string>() + "'");
  }
  const auto k = sensor_numbers(root["intrinsics"], "intrinsics", 4, path);
  s.fu = k[0];
  s.fv = k[1];
  s.cu = k[2];
  s.cv = k[3];
  if (s.fu <= 0 || s.fv <= 0) throw InputError(path.string(), "focal lengths must be positive");
  const std::string model = root["distortion_model"] ? root["distortion_model"].as<std::string>() : "radial-tangential";
  const auto lens = geometry::parse_lens_model(model);
  if (!lens) {
    throw InputError(path.string(),
                     "unsupported distortion_model '" + model + "' (expected radial-tangential or equidistant)");
  }
  s.distortion_model = *lens;
  const auto d = sensor_numbers(root["distortion_coefficients"], "distortion_coefficients", 4, path);
  std::copy(d.begin(), d.end(), s.distortion.begin());
  // Rectification needs the ray of every border pixel; a distortion that folds over inside the
  // image (a fit extrapolated past the calibration's data) would give wrong rays there.
  if (!s.lens().max_ray_angle()) {
    throw InputError(path.string(), fmt::format("the {} distortion {} folds over inside the {}x{} image: some pixels "
                                                "have no ray", model, fmt::join(d, ", "), s.width, s.height));
  }
  if (root["rate_hz"]) s.rate_hz = root["rate_hz"].as<double>();
  return s;
}

}  // namespace

EurocCameraSensor read_euroc_camera_yaml(const fs::path& path) {
  const YAML::Node root = detail::load_sensor_yaml(path);
  return with_yaml_errors_as_input_errors(path, [&] { return parse_camera_yaml(root, path); });
}

void write_euroc_camera_yaml(const fs::path& path, const EurocCameraSensor& s, const std::string& comment) {
  // Double-quoted, so that a colon or a '#' in the comment stays text.
  std::string quoted = "\"";
  for (const char c : comment) {
    if (c == '"' || c == '\\') quoted += '\\';
    quoted += c == '\n' ? ' ' : c;
  }
  quoted += '"';
  write_file_atomically(path, [&](std::ostream& out) {
    const Eigen::Matrix4d M = s.T_BS.matrix();
    out << "%YAML:1.0\n# General sensor definitions.\nsensor_type: camera\n"
        << "comment: " << quoted << "\n\n# Sensor extrinsics wrt. the body-frame.\nT_BS:\n  cols: 4\n  rows: 4\n  data: [";
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) out << fmt::format("{:.17g}", M(r, c)) << (r < 3 || c < 3 ? ", " : "");
      out << (r < 3 ? "\n         " : "]\n");
    }
    out << "\n# Camera specific definitions.\n";
    if (s.rate_hz > 0) out << fmt::format("rate_hz: {}\n", s.rate_hz);
    out << fmt::format("resolution: [{}, {}]\ncamera_model: pinhole\n", s.width, s.height)
        << fmt::format("intrinsics: [{:.17g}, {:.17g}, {:.17g}, {:.17g}] #fu, fv, cu, cv\n", s.fu, s.fv, s.cu, s.cv)
        << fmt::format("distortion_model: {}\ndistortion_coefficients: [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n",
                       geometry::to_string(s.distortion_model), s.distortion[0], s.distortion[1], s.distortion[2],
                       s.distortion[3]);
  });
}

Trajectory body_to_sensor(const Trajectory& body, const Eigen::Isometry3d& T_BS) {
  Trajectory out;
  out.reserve(body.size());
  for (const auto& sp : body) out.push_back({sp.t, sp.T * T_BS});
  return out;
}

Eigen::Isometry3d read_euroc_T_BS(const fs::path& path) {
  const YAML::Node root = detail::load_sensor_yaml(path);
  return with_yaml_errors_as_input_errors(path, [&] { return parse_sensor_T_BS(root, path); });
}

}  // namespace plslam::io
