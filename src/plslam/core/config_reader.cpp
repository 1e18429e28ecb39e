#include "plslam/core/config_reader.h"

#include <cmath>
#include <fstream>
#include <sstream>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/core/input_file.h"

namespace plslam {

ConfigReader::ConfigReader() : node_(YAML::NodeType::Map), state_(std::make_shared<State>()) {
  state_->source = "<defaults>";
}

ConfigReader::ConfigReader(YAML::Node node, std::shared_ptr<State> state, std::string prefix)
    : node_(std::move(node)), state_(std::move(state)), prefix_(std::move(prefix)) {}

ConfigReader ConfigReader::from_string(const std::string& yaml, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(yaml);
  } catch (const YAML::Exception& e) {
    throw InputError(source, fmt::format("malformed YAML at line {}: {}", e.mark.line + 1, e.msg));
  }
  if (root.IsNull()) root = YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw InputError(source, "malformed configuration: expected a mapping of sections");
  auto state = std::make_shared<State>();
  state->source = source;
  return ConfigReader(root, state, "");
}

ConfigReader ConfigReader::from_file(const std::filesystem::path& path) {
  std::ifstream in = open_text_file(path, "configuration file not found");
  std::stringstream ss;
  ss << in.rdbuf();
  return from_string(ss.str(), path.string());
}

std::string ConfigReader::full(const std::string& key) const { return prefix_.empty() ? key : prefix_ + "." + key; }

void ConfigReader::fail(const std::string& key, const std::string& problem) const {
  throw InputError(state_->source, fmt::format("{}: {}", full(key), problem));
}

YAML::Node ConfigReader::lookup(const std::string& key) const {
  if (!node_.IsMap()) return YAML::Node();
  YAML::Node child = node_[key];
  if (child) state_->used.insert(full(key));
  return child;
}

bool ConfigReader::has(const std::string& key) const { return node_.IsMap() && node_[key]; }

ConfigReader ConfigReader::section(const std::string& key) const {
  YAML::Node child = lookup(key);
  if (!child || child.IsNull()) return ConfigReader(YAML::Node(YAML::NodeType::Map), state_, full(key));
  if (!child.IsMap()) fail(key, "expected a section (a mapping of keys)");
  return ConfigReader(child, state_, full(key));
}

void ConfigReader::get(const std::string& key, bool& value) const {
  const YAML::Node n = lookup(key);
  if (!n) return;
  try {
    value = n.as<bool>();
  } catch (const YAML::Exception&) {
    fail(key, "expected true or false");
  }
}

void ConfigReader::get(const std::string& key, int& value) const {
  const YAML::Node n = lookup(key);
  if (!n) return;
  try {
    value = n.as<int>();
  } catch (const YAML::Exception&) {
    fail(key, "expected an integer");
  }
}

void ConfigReader::get(const std::string& key, double& value) const {
  const YAML::Node n = lookup(key);
  if (!n) return;
  double v = 0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(key, "expected a number");
  }
  if (!std::isfinite(v)) fail(key, "expected a finite number");
  value = v;
}

void ConfigReader::get(const std::string& key, std::string& value) const {
  const YAML::Node n = lookup(key);
  if (!n) return;
  if (!n.IsScalar()) fail(key, "expected a string");
  value = n.as<std::string>();
}

void ConfigReader::collect_unused(const YAML::Node& node, const std::string& prefix, std::string& first) const {
  if (!first.empty() || !node.IsMap()) return;
  for (const auto& kv : node) {
    // A key that is itself a map or a list ({a: 1}: 2) is never one plslam reads (found by fuzzing:
    // tests/fuzz/corpus/config/non_scalar_key.yaml).
    const std::string name = kv.first.IsScalar() ? kv.first.Scalar() : "<a map or list used as a key>";
    const std::string key = prefix.empty() ? name : prefix + "." + name;
    if (!state_->used.count(key)) {
      first = key;
      return;
    }
    collect_unused(kv.second, key, first);
  }
}

void ConfigReader::check_all_used() const {
  std::string first;
  collect_unused(node_, prefix_, first);
  if (!first.empty()) throw InputError(state_->source, fmt::format("unknown key '{}'", first));
}

}  // namespace plslam
