#include "plslam/bench/slam_configurations.h"

#include <algorithm>
#include <fstream>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "plslam/core/config_reader.h"
#include "plslam/core/error.h"
#include "plslam/system/system_config.h"

namespace plslam::bench {

std::vector<SlamConfiguration> builtin_slam_configurations() {
  return {
      {"full", "the default system: points and lines, SSC, PID and Kalman keyframes, loop closing", ""},
      {"no-lines", "points only", "lines: {enabled: false}\n"},
      {"quadtree", "ORB-SLAM2's quadtree keypoint distribution instead of SSC", "features: {distribution: quadtree}\n"},
      {"no-pid", "keyframe rule without the PID offset", "keyframe: {pid: false}\n"},
      {"no-kalman", "keyframe rule without the Kalman velocity trigger", "keyframe: {kalman: false}\n"},
      {"no-loop-closing", "local mapping only (odometry)", "loop: {enabled: false}\n"},
      {"stereo-inertial", "the IMU used where the input has one (mav0/imu0); without one, as stereo",
       "imu: {enabled: true}\n"},
      {"stereo", "the IMU left out (as --no-imu)", "imu: {enabled: false}\n"},
  };
}

bool valid_configuration_name(const std::string& name) {
  if (name.empty() || name.size() > 64 || name.front() == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '-' || c == '_' ||
           c == '.';
  });
}

void validate_slam_configuration(const SlamConfiguration& c, const std::string& source) {
  const std::string where = source + " (configuration " + c.name + ")";
  for (const auto format : {io::DatasetFormat::kEuroc, io::DatasetFormat::kKitti}) {
    const auto reader = ConfigReader::from_string(c.yaml, where);
    system::apply_config(reader, system::load_system_options(format, std::nullopt));
  }
}

bool disables_loop_closing(const SlamConfiguration& c) {
  const auto options = system::apply_config(ConfigReader::from_string(c.yaml, c.name),
                                            system::load_system_options(io::DatasetFormat::kEuroc, std::nullopt));
  return !options.loop_closing;
}

namespace {

std::vector<SlamConfiguration> parse_configurations(const YAML::Node& root, const std::string& src) {
  if (!root.IsMap() || !root["configs"] || !root["configs"].IsMap() || root["configs"].size() == 0) {
    throw InputError(src, "expected a non-empty map 'configs: {name: {overrides: {...}}}'");
  }
  for (const auto& kv : root) {
    if (!kv.first.IsScalar() || kv.first.Scalar() != "configs") throw InputError(src, "unknown key at the top: only 'configs'");
  }
  std::vector<SlamConfiguration> out;
  std::set<std::string> names;
  for (const auto& kv : root["configs"]) {
    if (!kv.first.IsScalar()) throw InputError(src, "configs: a name must be text");
    SlamConfiguration c;
    c.name = kv.first.Scalar();
    if (!valid_configuration_name(c.name)) {
      throw InputError(src, "configs." + c.name + ": a name holds letters, digits, '-', '_' or '.'");
    }
    if (!names.insert(c.name).second) throw InputError(src, "configs." + c.name + ": defined twice");
    const YAML::Node body = kv.second;
    if (!body.IsMap()) throw InputError(src, "configs." + c.name + ": expected a map with 'overrides'");
    for (const auto& field : body) {
      const std::string key = field.first.IsScalar() ? field.first.Scalar() : std::string("?");
      if (key != "description" && key != "overrides") throw InputError(src, "configs." + c.name + "." + key + ": unknown key");
    }
    if (body["description"]) {
      if (!body["description"].IsScalar()) throw InputError(src, "configs." + c.name + ".description: expected text");
      c.description = body["description"].Scalar();
    }
    if (body["overrides"]) {
      if (!body["overrides"].IsMap()) throw InputError(src, "configs." + c.name + ".overrides: expected a map");
      YAML::Emitter e;
      e << body["overrides"];
      if (!e.good()) throw InputError(src, "configs." + c.name + ".overrides: " + e.GetLastError());
      c.yaml = std::string(e.c_str()) + "\n";
    }
    validate_slam_configuration(c, src);
    out.push_back(std::move(c));
  }
  return out;
}

}  // namespace

std::vector<SlamConfiguration> parse_slam_configurations(const std::string& text, const std::string& source) {
  try {
    return parse_configurations(YAML::Load(text), source);
  } catch (const YAML::Exception& e) {
    throw InputError(source, std::string("malformed YAML: ") + e.msg);
  }
}

std::vector<SlamConfiguration> load_slam_configurations(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in || std::filesystem::is_directory(file)) throw InputError(file.string(), "cannot open the configurations file");
  std::ostringstream text;
  text << in.rdbuf();
  return parse_slam_configurations(text.str(), file.string());
}

std::vector<SlamConfiguration> select_slam_configurations(const std::string& list,
                                                          const std::vector<SlamConfiguration>& available) {
  if (list == "all") return available;
  std::vector<SlamConfiguration> out;
  std::set<std::string> seen;
  std::stringstream ss(list);
  std::string name;
  while (std::getline(ss, name, ',')) {
    if (name.empty()) throw InputError("--configs", "empty name in '" + list + "'");
    if (!seen.insert(name).second) throw InputError("--configs", "'" + name + "' is listed twice");
    auto it = std::find_if(available.begin(), available.end(), [&](const auto& c) { return c.name == name; });
    if (it == available.end()) {
      std::string names;
      for (const auto& c : available) names += (names.empty() ? "" : ", ") + c.name;
      throw InputError("--configs", "unknown configuration '" + name + "' (known: " + names + ")");
    }
    out.push_back(*it);
  }
  if (out.empty()) throw InputError("--configs", "no configuration selected");
  return out;
}

}  // namespace plslam::bench
