#include "plslam/io/camchain_file.h"

#include <cmath>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/io/atomic_file.h"
#include "plslam/io/sensor_yaml.h"

namespace plslam::io {
namespace {

namespace fs = std::filesystem;
using detail::sensor_numbers;

void check_keys(const YAML::Node& node, const std::set<std::string>& known, const std::string& where,
                const fs::path& path) {
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (!known.count(key)) throw InputError(path.string(), fmt::format("{}{}: unknown key", where, key));
  }
}

geometry::LensCamera parse_camera(const YAML::Node& cam, const std::string& name, const fs::path& path) {
  if (!cam || !cam.IsMap()) throw InputError(path.string(), fmt::format("{}: missing, or not a mapping", name));
  check_keys(cam,
             {"camera_model", "distortion_model", "distortion_coeffs", "distortion_coefficients", "intrinsics",
              "resolution", "T_cn_cnm1", "rostopic", "cam_overlaps", "T_cam_imu", "timeshift_cam_imu"},
             name + ".", path);
  const std::string model_key = name + ".camera_model";
  if (cam["camera_model"] && cam["camera_model"].as<std::string>() != "pinhole") {
    throw InputError(path.string(), fmt::format("{}: '{}' is not supported (pinhole only)", model_key,
                                                cam["camera_model"].as<std::string>()));
  }
  geometry::LensCamera lens;
  const auto res = sensor_numbers(cam["resolution"], (name + ".resolution").c_str(), 2, path);
  if (!(res[0] >= 1 && res[0] <= 100000 && res[1] >= 1 && res[1] <= 100000) || res[0] != std::floor(res[0]) ||
      res[1] != std::floor(res[1]))
    throw InputError(path.string(), name + ".resolution: must be two whole numbers in [1, 100000]");
  lens.width = static_cast<int>(res[0]);
  lens.height = static_cast<int>(res[1]);
  const auto k = sensor_numbers(cam["intrinsics"], (name + ".intrinsics").c_str(), 4, path);
  if (!(k[0] > 0 && k[1] > 0)) throw InputError(path.string(), name + ".intrinsics: focal lengths must be positive");
  lens.fx = k[0];
  lens.fy = k[1];
  lens.cx = k[2];
  lens.cy = k[3];
  const std::string dist = cam["distortion_model"] ? cam["distortion_model"].as<std::string>() : "none";
  if (dist == "none") {
    if (cam["distortion_coeffs"] || cam["distortion_coefficients"])
      throw InputError(path.string(), name + ".distortion_coeffs: given for distortion_model none");
    return lens;
  }
  const auto parsed = geometry::parse_lens_model(dist);
  if (!parsed) {
    throw InputError(path.string(), fmt::format("{}.distortion_model: '{}' is not supported (radtan, equidistant or "
                                                "none)", name, dist));
  }
  lens.model = *parsed;
  const char* coeff_key = cam["distortion_coeffs"] ? "distortion_coeffs" : "distortion_coefficients";
  const auto d = sensor_numbers(cam[coeff_key], (name + "." + coeff_key).c_str(), 4, path);
  std::copy(d.begin(), d.end(), lens.coeffs.begin());
  if (!lens.max_ray_angle()) {
    throw InputError(path.string(), fmt::format("{}: the {} distortion {} folds over inside the {}x{} image", name,
                                                dist, fmt::join(d, ", "), lens.width, lens.height));
  }
  return lens;
}

Eigen::Isometry3d parse_transform(const YAML::Node& node, const std::string& key, const fs::path& path) {
  if (!node || !node.IsSequence() || node.size() != 4)
    throw InputError(path.string(), key + ": missing, or not 4 rows of 4 numbers");
  Eigen::Matrix4d M;
  for (int r = 0; r < 4; ++r) {
    const auto row = sensor_numbers(node[static_cast<std::size_t>(r)], (key + " row").c_str(), 4, path);
    for (int c = 0; c < 4; ++c) M(r, c) = row[static_cast<std::size_t>(c)];
  }
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if ((R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3 || R.determinant() < 0 ||
      (M.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).norm() > 1e-9) {
    throw InputError(path.string(), key + ": not a rigid transform");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = M.topRightCorner<3, 1>();
  return T;
}

void write_camera(std::ostream& out, const geometry::LensCamera& lens) {
  out << "  camera_model: pinhole\n"
      << fmt::format("  distortion_model: {}\n",
                     lens.model == geometry::LensModel::kEquidistant ? "equidistant" : "radtan")
      << fmt::format("  distortion_coeffs: [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n", lens.coeffs[0], lens.coeffs[1],
                     lens.coeffs[2], lens.coeffs[3])
      << fmt::format("  intrinsics: [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n", lens.fx, lens.fy, lens.cx, lens.cy)
      << fmt::format("  resolution: [{}, {}]\n", lens.width, lens.height);
}

}  // namespace

bool is_camchain(const YAML::Node& root) { return root.IsMap() && root["cam0"]; }

geometry::RawStereoRig parse_camchain(const YAML::Node& root, const fs::path& path) {
  return detail::with_yaml_errors_as_input_errors(path, [&] {
    check_keys(root, {"cam0", "cam1"}, "", path);
    geometry::RawStereoRig rig;
    rig.left = parse_camera(root["cam0"], "cam0", path);
    if (root["cam0"]["T_cn_cnm1"]) throw InputError(path.string(), "cam0.T_cn_cnm1: only cam1 has one");
    rig.right = parse_camera(root["cam1"], "cam1", path);
    if (rig.left.width != rig.right.width || rig.left.height != rig.right.height) {
      throw InputError(path.string(), fmt::format("cam1.resolution: {}x{} differs from cam0's {}x{}", rig.right.width,
                                                  rig.right.height, rig.left.width, rig.left.height));
    }
    if (rig.left.model != rig.right.model) {
      throw InputError(path.string(), "cam1.distortion_model: differs from cam0's (a rig has one lens model)");
    }
    rig.T_right_left = parse_transform(root["cam1"]["T_cn_cnm1"], "cam1.T_cn_cnm1", path);
    return rig;
  });
}

geometry::RawStereoRig read_camchain_file(const fs::path& path) {
  return parse_camchain(detail::load_sensor_yaml(path), path);
}

void write_camchain_file(const fs::path& path, const geometry::RawStereoRig& rig, const std::string& comment) {
  write_file_atomically(path, [&](std::ostream& out) {
    std::istringstream lines(comment);
    for (std::string line; std::getline(lines, line);) out << "# " << line << '\n';
    out << "cam0:\n";
    write_camera(out, rig.left);
    out << "cam1:\n";
    write_camera(out, rig.right);
    out << "  T_cn_cnm1:\n";
    const Eigen::Matrix4d M = rig.T_right_left.matrix();
    for (int r = 0; r < 4; ++r)
      out << fmt::format("  - [{:.17g}, {:.17g}, {:.17g}, {:.17g}]\n", M(r, 0), M(r, 1), M(r, 2), M(r, 3));
  });
}

}  // namespace plslam::io
