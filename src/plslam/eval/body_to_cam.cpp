#include "plslam/eval/body_to_cam.h"

#include <fstream>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "plslam/core/error.h"

namespace plslam::eval {

Eigen::Isometry3d read_euroc_T_BS(const std::filesystem::path& sensor_yaml) {
  const std::string file = sensor_yaml.string();
  std::ifstream in(sensor_yaml);
  if (!in) throw InputError(file, "cannot open sensor.yaml");
  // EuRoC files start with OpenCV's "%YAML:1.0", which is not a valid YAML directive.
  std::stringstream text;
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind("%YAML", 0) == 0) continue;
    text << line << '\n';
  }
  YAML::Node root;
  try {
    root = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    throw InputError(file, std::string("invalid YAML: ") + e.what());
  }
  const YAML::Node data = root["T_BS"] ? root["T_BS"]["data"] : YAML::Node();
  if (!data || !data.IsSequence() || data.size() != 16) {
    throw InputError(file, "no T_BS with 16 numbers in 'data'");
  }
  Eigen::Matrix4d M;
  try {
    for (int r = 0; r < 4; ++r) {
      for (int c = 0; c < 4; ++c) M(r, c) = data[static_cast<std::size_t>(r * 4 + c)].as<double>();
    }
  } catch (const YAML::Exception&) {
    throw InputError(file, "T_BS data holds a non-number");
  }
  const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
  if (!M.allFinite() || (R.transpose() * R - Eigen::Matrix3d::Identity()).norm() > 1e-3 ||
      std::abs(R.determinant() - 1.0) > 1e-3 || !M.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1))) {
    throw InputError(file, "T_BS is not a rigid transform");
  }
  // Re-orthonormalise the 12-digit rotation so that composed poses stay rigid.
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = M.topRightCorner<3, 1>();
  return T;
}

Trajectory body_to_camera(const Trajectory& body, const Eigen::Isometry3d& T_BS) {
  Trajectory out = body;
  for (auto& p : out) p.T = p.T * T_BS;
  return out;
}

}  // namespace plslam::eval
