// The table of configuration keys against the parser, the shipped presets, the header and the
// CLI: a key cannot be listed without being read, nor read without being listed.
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <sstream>
#include <set>

#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include "plslam/core/config_reader.h"
#include "plslam/core/error.h"
#include "plslam/system/system_config.h"
#include "support/test_support.h"

namespace plslam::system {
namespace config_keys_test {

using Values = std::map<std::string, std::string>;

Values values_of(const SystemOptions& o) {
  Values v;
  for (const auto& [key, value] : config_values(o)) v[key] = value;
  return v;
}

// A YAML document setting each (section.name, value text) pair; strings double-quoted.
std::string yaml_of(const std::vector<std::pair<std::string, std::string>>& entries) {
  std::map<std::string, std::string> type;
  for (const auto& k : config_keys()) type[k.key] = k.type;
  std::map<std::string, std::string> sections;
  for (const auto& [key, value] : entries) {
    const auto dot = key.find('.');
    const std::string text = type.at(key) == "string" ? "\"" + value + "\"" : value;
    sections[key.substr(0, dot)] += fmt::format("  {}: {}\n", key.substr(dot + 1), text);
  }
  std::string yaml;
  for (const auto& [section, body] : sections) yaml += section + ":\n" + body;
  return yaml;
}

SystemOptions apply_yaml(const std::string& yaml, const SystemOptions& preset) {
  return apply_config(ConfigReader::from_string(yaml, "test.yaml"), preset);
}

TEST(ConfigKeys, EveryKeyIsListedOnceWithItsPresetsDefaults) {
  const auto keys = config_keys();
  std::set<std::string> names;
  for (const auto& k : keys) {
    EXPECT_TRUE(names.insert(k.key).second) << k.key << " listed twice";
    EXPECT_FALSE(k.description.empty()) << k.key;
    EXPECT_NE(k.key.find('.'), std::string::npos) << k.key;
  }
  const Values euroc = values_of(SystemOptions::euroc()), kitti = values_of(SystemOptions::kitti());
  for (const auto& k : keys) {
    EXPECT_EQ(k.euroc, euroc.at(k.key));
    EXPECT_EQ(k.kitti, kitti.at(k.key));
  }
  // The keys that turned tuned numbers into options, and the ones the old header comment missed.
  for (const char* key : {"tracking.far_stereo_baselines", "mapping.culling_close_depth_baselines",
                          "mapping.triangulation_max_hamming", "mapping.recent_min_found_ratio",
                          "tracking.reference_match_ratio", "loop.global_ba_iterations",
                          "relocalization.gate_margin"}) {
    EXPECT_TRUE(names.count(key)) << key;
  }
}

TEST(ConfigKeys, EveryKeySetToItsDefaultRoundTrips) {
  for (const SystemOptions& preset : {SystemOptions::euroc(), SystemOptions::kitti()}) {
    const auto defaults = config_values(preset);
    const SystemOptions read = apply_yaml(yaml_of(defaults), preset);
    EXPECT_EQ(values_of(read), values_of(preset));
  }
}

// Values of the key's type that differ from `current`, most likely valid first.
std::vector<std::string> changed_values(const std::string& type, const std::string& current) {
  if (type == "bool") return {current == "true" ? "false" : "true"};
  if (type == "int") {
    const int v = std::stoi(current);
    return {fmt::format("{}", v + 1), fmt::format("{}", v - 1), fmt::format("{}", v + 10)};
  }
  if (type == "double") {
    const double v = std::stod(current);
    std::vector<std::string> out;
    for (double c : {v * 1.5, v * 0.5, v + 1, v + 0.5, v - 0.5, 0.5}) {
      if (c != v) out.push_back(fmt::format("{}", c));
    }
    return out;
  }
  return {current == "ssc" ? "quadtree" : "ssc", "elsewhere.plvoc"};
}

TEST(ConfigKeys, EveryKeyIsReadIntoItsOwnOption) {
  const SystemOptions preset = SystemOptions::euroc();
  const Values before = values_of(preset);
  for (const auto& k : config_keys()) {
    bool changed = false;
    for (const auto& value : changed_values(k.type, before.at(k.key))) {
      Values after;
      try {
        after = values_of(apply_yaml(yaml_of({{k.key, value}}), preset));
      } catch (const InputError&) {
        continue;  // not a valid value for this key: try the next
      }
      if (after.at(k.key) != value) continue;
      changed = true;
      for (const auto& [other, text] : before) {
        if (other == k.key) continue;
        EXPECT_EQ(after.at(other), text) << "setting " << k.key << " changed " << other;
      }
      break;
    }
    EXPECT_TRUE(changed) << k.key << " was never read into the option the table names";
  }
}

// The two bounds of "in [a, b]" / "in (a, b]", opened by `open`; nullopt for another form. (No
// std::regex: GCC 12 warns inside <regex> under the sanitizers' -O1, and warnings are errors.)
std::optional<std::pair<double, double>> range_of(const std::string& valid, char open) {
  const std::string head = std::string("in ") + open;
  if (valid.rfind(head, 0) != 0 || valid.back() != ']') return std::nullopt;
  const auto comma = valid.find(", ");
  if (comma == std::string::npos) return std::nullopt;
  return std::pair{std::stod(valid.substr(head.size(), comma - head.size())), std::stod(valid.substr(comma + 2))};
}

// A value outside what `valid` (">= x", "positive", "in [a, b]", "in (a, b]") accepts.
std::optional<std::string> invalid_value(const std::string& type, const std::string& valid) {
  const double step = type == "int" ? 1 : 0.5;
  if (valid.rfind(">= ", 0) == 0) return fmt::format("{}", std::stod(valid.substr(3)) - step);
  if (valid == "positive") return "0";
  if (const auto r = range_of(valid, '[')) return fmt::format("{}", r->second + step);
  if (const auto r = range_of(valid, '(')) return fmt::format("{}", r->first);
  return std::nullopt;
}

TEST(ConfigKeys, EachCheckRejectsAValueOutsideItsRangeNamingTheFileAndKey) {
  int checked = 0;
  for (const auto& k : config_keys()) {
    if (k.valid.empty() || k.type == "string") continue;
    const auto bad = invalid_value(k.type, k.valid);
    ASSERT_TRUE(bad) << k.key << ": cannot read '" << k.valid << "'";
    try {
      apply_yaml(yaml_of({{k.key, *bad}}), SystemOptions::euroc());
      ADD_FAILURE() << k.key << ": " << *bad << " was accepted (" << k.valid << ")";
    } catch (const InputError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find("test.yaml"), std::string::npos) << what;
      EXPECT_NE(what.find(k.key + ": must be " + k.valid), std::string::npos) << what;
    }
    ++checked;
  }
  EXPECT_GT(checked, 30);
}

// The shipped files may leave keys out (every key has its default in code); every key they
// mention is in the table, and its value is the preset's, so that a file documents its preset.
TEST(ConfigKeys, ShippedConfigFilesMentionOnlyTableKeysWithThePresetsValues) {
  std::set<std::string> table;
  for (const auto& k : config_keys()) table.insert(k.key);
  for (const auto& [file, preset] : {std::pair{"euroc.yaml", SystemOptions::euroc()},
                                     std::pair{"kitti.yaml", SystemOptions::kitti()}}) {
    const auto path = std::filesystem::path(PLSLAM_SOURCE_DIR) / "config" / file;
    const YAML::Node root = YAML::LoadFile(path.string());
    int mentioned = 0;
    for (const auto& section : root) {
      for (const auto& key : section.second) {
        const std::string name = section.first.as<std::string>() + "." + key.first.as<std::string>();
        EXPECT_TRUE(table.count(name)) << file << " mentions " << name << ", which is not in the table";
        ++mentioned;
      }
    }
    EXPECT_GT(mentioned, 40) << file;
    EXPECT_EQ(values_of(apply_config(ConfigReader::from_file(path), preset)), values_of(preset)) << file;
  }
}

TEST(ConfigKeys, TheHeaderPointsToTheTableInsteadOfListingKeys) {
  const std::string header =
      test::read_file(std::filesystem::path(PLSLAM_SOURCE_DIR) / "src/plslam/system/system_config.h");
  ASSERT_FALSE(header.empty());
  EXPECT_NE(header.find("config_keys()"), std::string::npos);
  EXPECT_NE(header.find("plslam config keys"), std::string::npos);
  for (const auto& k : config_keys()) {
    const std::string name = k.key.substr(k.key.find('.') + 1);
    if (name.find('_') == std::string::npos) continue;  // "enabled", "ratio": ordinary words
    EXPECT_EQ(header.find(name), std::string::npos) << "the header names the key " << k.key;
  }
  // A hand-written list looked like "//   features: {n_points, levels, ...}".
  std::istringstream lines(header);
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("//", 0) != 0) continue;
    const auto colon = line.find(": {");
    const auto word = line.find_first_not_of("/ ");
    const bool listed = colon != std::string::npos && word < colon &&
                        line.find_first_not_of("abcdefghijklmnopqrstuvwxyz_", word) == colon;
    EXPECT_FALSE(listed) << "a hand-written key list: " << line;
  }
}

TEST(ConfigKeys, CliListsTheTable) {
  const auto keys = config_keys();
  const auto json = test::run_cli("config keys --json");
  ASSERT_EQ(json.exit_code, 0) << json.err;
  const auto j = nlohmann::json::parse(json.out);
  ASSERT_EQ(j.size(), keys.size());
  for (std::size_t i = 0; i < keys.size(); ++i) {
    EXPECT_EQ(j[i]["key"], keys[i].key);
    EXPECT_EQ(j[i]["type"], keys[i].type);
    EXPECT_EQ(j[i]["valid"], keys[i].valid);
  }
  EXPECT_EQ(j[0]["default"]["kitti"], 2000);  // features.n_points, as a number
  const auto text = test::run_cli("config keys");
  ASSERT_EQ(text.exit_code, 0) << text.err;
  for (const auto& k : keys) EXPECT_NE(text.out.find(k.key), std::string::npos) << k.key;
}

}  // namespace config_keys_test
}  // namespace plslam::system
