#include "plslam/system/system_config.h"

#include <cstdlib>
#include <filesystem>
#include <system_error>
#include <variant>
#include <vector>

#include <fmt/format.h>

#include "plslam/core/error.h"
#include "plslam/system/config_table.h"

namespace plslam::system {

namespace {

// Reads one key into `o` (the option keeps its value when the key is absent), checks and stores it.
void read_key(const ConfigReader& section, const ConfigKey& k, SystemOptions& o, const std::string& file) {
  ConfigValue v = k.get(o);
  std::visit([&](auto& x) { section.get(k.name, x); }, v);
  if (k.check && !k.check->ok(v)) throw InputError(file, k.key() + ": " + k.check->problem);
  if (k.check_message) {
    if (const std::string problem = k.check_message(v); !problem.empty()) throw InputError(file, problem);
  }
  k.set(o, v, file);
}

}  // namespace

SystemOptions apply_config(const ConfigReader& config, SystemOptions o) {
  const auto& table = config_table();
  for (std::size_t i = 0; i < table.size();) {
    const std::string name = table[i].section;
    const ConfigReader section = config.section(name);
    for (; i < table.size() && table[i].section == name; ++i) read_key(section, table[i], o, config.source());
    for (const auto& c : section_checks()) {
      if (c.section == name) c.check(o, config.source());
    }
  }
  config.check_all_used();
  return o;
}

std::vector<ConfigKeyInfo> config_keys() {
  const SystemOptions euroc = SystemOptions::euroc(), kitti = SystemOptions::kitti();
  std::vector<ConfigKeyInfo> out;
  for (const auto& k : config_table()) {
    std::string valid;
    if (k.check) {
      valid = k.check->problem;
      if (valid.rfind("must be ", 0) == 0) valid = valid.substr(8);
    } else {
      valid = k.valid_values;
    }
    out.push_back({k.key(), to_string(k.type), to_yaml_text(k.get(euroc)), to_yaml_text(k.get(kitti)), valid,
                   k.description});
  }
  return out;
}

std::vector<std::pair<std::string, std::string>> config_values(const SystemOptions& options) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& k : config_table()) out.emplace_back(k.key(), to_yaml_text(k.get(options)));
  return out;
}

std::filesystem::path shipped_data_file(const std::filesystem::path& relative) {
  // PLSLAM_DATA_DIR (<prefix>/share/plslam) names an installed copy explicitly, for a prefix moved
  // after the build.
  if (const char* dir = std::getenv("PLSLAM_DATA_DIR"); dir && *dir) return std::filesystem::path(dir) / relative;
  // The source tree's data/ (PLSLAM_DEFAULT_VOCABULARY is data/vocabulary/<file>), then the
  // installed copy: beside the running program (<prefix>/bin/../share/plslam, wherever the prefix
  // was moved) or at the configured prefix (a program that embeds the library and lives elsewhere).
  const std::filesystem::path source_data = std::filesystem::path(PLSLAM_DEFAULT_VOCABULARY).parent_path().parent_path();
  std::vector<std::filesystem::path> candidates = {source_data / relative};
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) candidates.push_back(exe.parent_path().parent_path() / "share/plslam" / relative);
  const std::filesystem::path installed = std::filesystem::path(PLSLAM_INSTALL_DATA_DIR) / relative;
  candidates.push_back(installed);
  for (const auto& c : candidates) {
    if (std::filesystem::is_regular_file(c, ec)) return c;
  }
  return installed;  // missing: loading it names this path
}

std::filesystem::path default_vocabulary_path() {
  return shipped_data_file(std::filesystem::path("vocabulary") / std::filesystem::path(PLSLAM_DEFAULT_VOCABULARY).filename());
}

std::shared_ptr<const place::Vocabulary> load_vocabulary(const SystemOptions& o) {
  if (!o.place_recognition) return nullptr;
  const auto path = o.vocabulary.empty() ? default_vocabulary_path() : o.vocabulary;
  return std::make_shared<const place::Vocabulary>(place::Vocabulary::load(path));
}

SystemOptions load_system_options(io::DatasetFormat format, const std::optional<std::filesystem::path>& file) {
  const SystemOptions preset = format == io::DatasetFormat::kKitti ? SystemOptions::kitti() : SystemOptions::euroc();
  return apply_config(file ? ConfigReader::from_file(*file) : ConfigReader(), preset);
}

}  // namespace plslam::system
