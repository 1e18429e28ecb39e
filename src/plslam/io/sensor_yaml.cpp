#include "plslam/io/sensor_yaml.h"

#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "plslam/core/input_file.h"

namespace plslam::io::detail {

YAML::Node load_sensor_yaml(const std::filesystem::path& path, const char* missing) {
  std::ifstream in = open_text_file(path, missing);
  std::stringstream ss;
  std::string line;
  bool first = true;
  while (std::getline(in, line)) {
    strip_cr(line);
    // Kept as a blank line, so that the parser's line numbers are the file's.
    if (first && line.rfind("%YAML", 0) == 0) line.clear();
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

std::vector<double> sensor_numbers(const YAML::Node& node, const char* key, std::size_t expected,
                                   const std::filesystem::path& path) {
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

Eigen::Isometry3d parse_sensor_T_BS(const YAML::Node& root, const std::filesystem::path& path) {
  const auto T = root["T_BS"];
  if (!T) throw InputError(path.string(), "missing 'T_BS'");
  if (!T.IsMap()) throw InputError(path.string(), "'T_BS' is not a map with rows, cols and data");
  const auto d = sensor_numbers(T["data"], "T_BS.data", 16, path);
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

}  // namespace plslam::io::detail
