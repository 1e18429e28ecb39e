// plslam config keys [--json]: every key of the YAML configuration of `plslam run`, with its type,
// the default of each preset, what it accepts and what it means (system::config_keys()).
#include <algorithm>
#include <iostream>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "command_registry.h"
#include "json_stdout.h"
#include "plslam/system/system_config.h"

namespace plslam::cli {
namespace {

int run_config_keys(bool json) {
  const auto keys = system::config_keys();
  if (json) {
    nlohmann::json j = nlohmann::json::array();
    // Defaults as JSON values of the key's type.
    const auto value = [](const system::ConfigKeyInfo& k, const std::string& text) {
      return k.type == "string" ? nlohmann::json(text) : nlohmann::json::parse(text);
    };
    for (const auto& k : keys) {
      j.push_back({{"key", k.key},
                   {"type", k.type},
                   {"default", {{"euroc", value(k, k.euroc)}, {"kitti", value(k, k.kitti)}}},
                   {"valid", k.valid},
                   {"description", k.description}});
    }
    print_json(j.dump(2) + "\n");
    return 0;
  }
  std::size_t key_width = 3, default_width = 5;
  for (const auto& k : keys) {
    key_width = std::max(key_width, k.key.size());
    default_width = std::max({default_width, k.euroc.size(), k.kitti.size()});
  }
  const auto row = [&](const std::string& key, const std::string& type, const std::string& euroc,
                       const std::string& kitti, const std::string& rest) {
    std::cout << fmt::format("{:<{}}  {:<6}  {:<{}}  {:<{}}  {}\n", key, key_width, type, euroc, default_width, kitti,
                             default_width, rest);
  };
  row("key", "type", "euroc", "kitti", "description");
  for (const auto& k : keys) {
    row(k.key, k.type, k.euroc.empty() ? "\"\"" : k.euroc, k.kitti.empty() ? "\"\"" : k.kitti,
        k.valid.empty() ? k.description : fmt::format("{} ({})", k.description, k.valid));
  }
  return 0;
}

CommandRegistration register_config_command({"config", "The configuration keys of plslam run", [](CLI::App& sub) {
                           sub.require_subcommand(1);
                           auto json = std::make_shared<bool>(false);
                           CLI::App* keys = sub.add_subcommand(
                               "keys", "Every key with its type, the presets' defaults, what it accepts and means");
                           keys->add_flag("--json", *json, "Print a JSON array");
                           return std::function<int()>([json] { return run_config_keys(*json); });
                         }});

}  // namespace
}  // namespace plslam::cli
