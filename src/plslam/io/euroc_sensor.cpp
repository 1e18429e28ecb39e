#include "plslam/io/euroc_sensor.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include "plslam/core/error.h"
#include "plslam/io/text_table.h"

namespace plslam::io {
namespace {

namespace fs = std::filesystem;

// ASL files start with OpenCV's "%YAML:1.0" directive, which is not valid YAML 1.2: drop it.
YAML::Node load_yaml(const fs::path& path) {
  std::ifstream in = open_text_file(path);
  std::stringstream ss;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    strip_cr(line);
    if (first && line.rfind("%YAML", 0) == 0) {
      first = false;
      continue;
    }
    first = false;
    ss << line << '\n';
  }
  try {
    YAML::Node node = YAML::Load(ss.str());
    if (!node.IsMap()) throw InputError(path.string(), "malformed YAML: expected a mapping at the top level");
    return node;
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), fmt::format("malformed YAML at line {}: {}", e.mark.line + 1, e.msg));
  }
}

std::vector<double> numbers(const YAML::Node& node, const char* key, std::size_t expected,
                            const fs::path& path) {
  if (!node || !node.IsSequence()) throw InputError(path.string(), fmt::format("missing or malformed '{}'", key));
  if (node.size() != expected) {
    throw InputError(path.string(), fmt::format("'{}' needs {} numbers, found {}", key, expected, node.size()));
  }
  std::vector<double> out;
  for (const auto& v : node) {
    double x = 0;
    try {
      x = v.as<double>();
    } catch (const YAML::Exception&) {
      throw InputError(path.string(), fmt::format("'{}' holds a non-number '{}'", key, v.Scalar()));
    }
    if (!std::isfinite(x)) throw InputError(path.string(), fmt::format("'{}' holds a non-finite value", key));
    out.push_back(x);
  }
  return out;
}

Eigen::Isometry3d parse_T_BS(const YAML::Node& root, const fs::path& path) {
  const auto T = root["T_BS"];
  if (!T) throw InputError(path.string(), "missing 'T_BS'");
  if (!T.IsMap()) throw InputError(path.string(), "'T_BS' is not a map with rows, cols and data");
  const auto d = numbers(T["data"], "T_BS.data", 16, path);
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) M(r, c) = d[r * 4 + c];
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3 || R.determinant() < 0 ||
      (M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    throw InputError(path.string(), "T_BS is not a rigid transform");
  }
  Eigen::Isometry3d iso = Eigen::Isometry3d::Identity();
  // Re-orthonormalise: the file's 12 digits are close to, not exactly, a rotation.
  iso.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  iso.translation() = M.topRightCorner<3, 1>();
  return iso;
}

// yaml-cpp throws on a value of the wrong shape (a list where a string is expected, a key on a
// scalar): that is the file's problem, reported as one line naming it (found by fuzzing,
// tests/fuzz/corpus/euroc_sensor/).
template <class F>
auto with_yaml_errors_as_input_errors(const fs::path& path, F&& body) {
  try {
    return body();
  } catch (const YAML::Exception& e) {
    throw InputError(path.string(), "malformed sensor.yaml: " + e.msg);
  }
}

EurocCameraSensor parse_camera_yaml(const YAML::Node& root, const fs::path& path) {
  EurocCameraSensor s;
  s.T_BS = parse_T_BS(root, path);
  const auto res = numbers(root["resolution"], "resolution", 2, path);
  if (!(res[0] >= 1 && res[0] <= 100000 && res[1] >= 1 && res[1] <= 100000) || res[0] != std::floor(res[0]) ||
      res[1] != std::floor(res[1]))
    throw InputError(path.string(), "resolution must be two whole numbers in [1, 100000]");
  s.width = static_cast<int>(res[0]);
  s.height = static_cast<int>(res[1]);
  if (root["camera_model"] && root["camera_model"].as<std::string>() != "pinhole") {
    throw InputError(path.string(), "unsupported camera_model '" + root["camera_model"].as<std::string>() + "'");
  }
  const auto k = numbers(root["intrinsics"], "intrinsics", 4, path);
  s.fu = k[0];
  s.fv = k[1];
  s.cu = k[2];
  s.cv = k[3];
  if (s.fu <= 0 || s.fv <= 0) throw InputError(path.string(), "focal lengths must be positive");
  const std::string model = root["distortion_model"] ? root["distortion_model"].as<std::string>() : "radial-tangential";
  if (model != "radial-tangential" && model != "radtan") {
    throw InputError(path.string(), "unsupported distortion_model '" + model + "' (expected radial-tangential)");
  }
  const auto d = numbers(root["distortion_coefficients"], "distortion_coefficients", 4, path);
  std::copy(d.begin(), d.end(), s.distortion.begin());
  if (root["rate_hz"]) s.rate_hz = root["rate_hz"].as<double>();
  return s;
}

}  // namespace

EurocCameraSensor read_euroc_camera_yaml(const fs::path& path) {
  const YAML::Node root = load_yaml(path);
  return with_yaml_errors_as_input_errors(path, [&] { return parse_camera_yaml(root, path); });
}

Trajectory body_to_sensor(const Trajectory& body, const Eigen::Isometry3d& T_BS) {
  Trajectory out;
  out.reserve(body.size());
  for (const auto& sp : body) out.push_back({sp.t, sp.T * T_BS});
  return out;
}

Eigen::Isometry3d read_euroc_T_BS(const fs::path& path) {
  const YAML::Node root = load_yaml(path);
  return with_yaml_errors_as_input_errors(path, [&] { return parse_T_BS(root, path); });
}

}  // namespace plslam::io
