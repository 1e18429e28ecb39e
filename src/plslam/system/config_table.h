#pragma once
// The one table of `plslam run`'s configuration keys: where each key lives in SystemOptions, its
// type, what it means and what values it accepts. apply_config() reads the YAML through it and
// config_keys() lists it, so the two cannot drift apart.
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "plslam/system/slam_system.h"

namespace plslam::system {

enum class ConfigType { kBool, kInt, kDouble, kString };
const char* to_string(ConfigType t);

using ConfigValue = std::variant<bool, int, double, std::string>;

// A condition on a key's value; `problem` (e.g. "must be >= 0") completes the message
// "section.key: problem".
struct ConfigCheck {
  std::function<bool(const ConfigValue&)> ok;
  std::string problem;
};

struct ConfigKey {
  std::string section;
  std::string name;
  ConfigType type;
  std::string description;
  // The key's value in the options, and how a value goes back (after `check`). `file` is the
  // configuration file's path, for values relative to it.
  std::function<ConfigValue(const SystemOptions&)> get;
  std::function<void(SystemOptions&, const ConfigValue&, const std::string& file)> set;
  std::optional<ConfigCheck> check;
  // A check whose message is not "section.key: problem" (kept as it always read): returns the
  // whole message, or "" when the value is fine.
  std::function<std::string(const ConfigValue&)> check_message;
  std::string valid_values;  // what check_message accepts, for the listing

  std::string key() const { return section + "." + name; }
};

// Every key, section by section, in the order apply_config() reads them (which decides which
// problem of a file with several is reported).
const std::vector<ConfigKey>& config_table();

// Conditions between the keys of a section, checked once all of them are read: throws InputError
// naming `file`.
struct SectionCheck {
  std::string section;
  std::function<void(const SystemOptions&, const std::string& file)> check;
};
const std::vector<SectionCheck>& section_checks();

// A value as YAML text: true/false, integers, doubles in their shortest exact form, strings as is.
std::string to_yaml_text(const ConfigValue& v);

}  // namespace plslam::system
