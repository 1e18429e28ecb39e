#pragma once
// The configurations `plslam bench slam` compares: each is a named set of overrides of the
// dataset's preset, written as the YAML that `plslam run --config` reads. The built-in ones switch
// off one part of the system each, to show what that part is worth; users add their own in a file.
#include <filesystem>
#include <string>
#include <vector>

namespace plslam::bench {

struct SlamConfiguration {
  std::string name;
  std::string description;
  std::string yaml;  // overrides of the preset ("" for none)
};

// full, no-lines, quadtree, no-pid, no-kalman, no-loop-closing, stereo-inertial, stereo.
std::vector<SlamConfiguration> builtin_slam_configurations();

// A YAML file of user configurations:
//   configs:
//     my-name:
//       description: "..."        # optional
//       overrides: {keyframe: {ratio: 0.8}}
// Every configuration is checked against both presets (unknown keys and bad values fail, naming
// the file and the configuration). Paths inside the overrides must be absolute.
std::vector<SlamConfiguration> load_slam_configurations(const std::filesystem::path& file);
// The same from the file's text (`source` names it in errors); the parser the fuzzer drives.
std::vector<SlamConfiguration> parse_slam_configurations(const std::string& text, const std::string& source);

// `list` is "all" or comma-separated names from `available`, in the order given. Throws
// InputError naming an unknown or repeated name.
std::vector<SlamConfiguration> select_slam_configurations(const std::string& list,
                                                          const std::vector<SlamConfiguration>& available);

// Throws InputError (source: `source`) when the overrides do not apply to the EuRoC or KITTI preset.
void validate_slam_configuration(const SlamConfiguration& c, const std::string& source);

// Whether the configuration switches loop closing off (it is then compared with an anchor run
// without loop closing).
bool disables_loop_closing(const SlamConfiguration& c);

// Names are used as folder names: letters, digits, '-', '_' and '.', not starting with '.'.
bool valid_configuration_name(const std::string& name);

}  // namespace plslam::bench
