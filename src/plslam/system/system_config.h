#pragma once
// The YAML configuration of `plslam run`: one section per module, defaults in code (the preset
// for the dataset), unknown keys rejected with their name. The keys, their types, defaults and
// meaning come from one table (config_table.h): list them with config_keys() or
// `plslam config keys [--json]`.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "plslam/core/config_reader.h"
#include "plslam/place/vocabulary.h"
#include "plslam/system/slam_system.h"

namespace plslam::system {

// Applies `config` on top of `preset`, validates, and fails on unknown keys.
SystemOptions apply_config(const ConfigReader& config, SystemOptions preset);

struct ConfigKeyInfo {
  std::string key;          // "section.name"
  std::string type;         // bool, int, double or string
  std::string euroc;        // the default of each preset, as YAML text
  std::string kitti;
  // What it accepts, e.g. ">= 0", "in [0, 1]"; empty: any value of its type, or a condition on
  // several keys of its section (keyframe, loop and ORB options are checked as a whole).
  std::string valid;
  std::string description;
};
// Every key apply_config() reads, in its order.
std::vector<ConfigKeyInfo> config_keys();
// Each key's value in `options`, as YAML text, in config_keys() order: (key, value).
std::vector<std::pair<std::string, std::string>> config_values(const SystemOptions& options);

// A file plslam ships under data/ (installed to <prefix>/share/plslam), by its path below it
// ("vocabulary/...", "published/..."): $PLSLAM_DATA_DIR's when set, else the source tree's copy (a
// build tree), else the installed one beside the running program or at the configured prefix; the
// configured prefix's path when none exists (loading it names that path).
std::filesystem::path shipped_data_file(const std::filesystem::path& relative);
// The vocabulary plslam ships (data/vocabulary/, see README: place recognition).
std::filesystem::path default_vocabulary_path();
// The vocabulary the options ask for (null with place recognition off); InputError naming the
// file when it is missing, truncated or not a vocabulary.
std::shared_ptr<const place::Vocabulary> load_vocabulary(const SystemOptions& options);

// The preset for a dataset format, overridden by the file when given.
SystemOptions load_system_options(io::DatasetFormat format, const std::optional<std::filesystem::path>& file);

}  // namespace plslam::system
