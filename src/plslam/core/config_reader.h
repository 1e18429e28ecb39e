#pragma once
// Reads a YAML configuration into option structs that hold their own defaults. Every key a reader
// consumes is remembered, so that after all modules have read their sections, any key nobody asked
// for is reported as an error naming it (a typo must never silently fall back to a default).
#include <filesystem>
#include <memory>
#include <set>
#include <string>

#include <yaml-cpp/yaml.h>

namespace plslam {

class ConfigReader {
 public:
  // An empty configuration: every get() leaves the default.
  ConfigReader();
  // Throws InputError naming the file on a missing file or malformed YAML.
  static ConfigReader from_file(const std::filesystem::path& path);
  static ConfigReader from_string(const std::string& yaml, const std::string& source = "<string>");

  // The sub-section `key` (e.g. "features"); an absent section reads as empty.
  ConfigReader section(const std::string& key) const;

  // Whether `key` is present (without marking it as read): for files where a key is required.
  bool has(const std::string& key) const;

  // Overwrites `value` when `key` is present. A value of the wrong type throws InputError naming
  // the file and the full key, e.g. "features.n_points: expected an integer".
  void get(const std::string& key, bool& value) const;
  void get(const std::string& key, int& value) const;
  void get(const std::string& key, double& value) const;
  void get(const std::string& key, std::string& value) const;

  // Throws InputError for the first key in the file that no get()/section() asked for.
  void check_all_used() const;

  const std::string& source() const { return state_->source; }
  // The dotted path of this section, e.g. "keyframe" ("" at the root).
  const std::string& prefix() const { return prefix_; }

 private:
  struct State {
    std::string source;
    std::set<std::string> used;
  };
  ConfigReader(YAML::Node node, std::shared_ptr<State> state, std::string prefix);
  std::string full(const std::string& key) const;
  YAML::Node lookup(const std::string& key) const;
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const;
  void collect_unused(const YAML::Node& node, const std::string& prefix, std::string& first) const;

  YAML::Node node_;
  std::shared_ptr<State> state_;
  std::string prefix_;
};

}  // namespace plslam
